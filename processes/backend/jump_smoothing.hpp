// Jump smoothing of seed 000 (section "pipeline"), the strategy of trajectory_prep.hpp for a
// scanner's stream (scans a few centimetres apart, tens per second).
//
// A scan matcher without a backend recovers from accumulated drift at a loop with a discrete
// jump. Each step between consecutive poses is compared with the average of the preceding steps
// (as velocities, so uneven scan timing does not matter); a step much longer, or in a clearly
// different direction, is replaced by that average, and the rest of the trajectory is carried
// along so it stays continuous. A single bad pose that the next pose returns from (it lies off
// the path between its neighbours by more than half that path's length) is an outlier, not a
// jump: it is replaced by interpolating its neighbours, and nothing after it moves. Deviations
// from the average motion below min_jump_m / min_jump_rad are never jumps: they are
// scan-matching noise that the backend's own matching handles.
//
// On a log subsampled by travel (a scan kept every metre or half radian, seconds apart) every
// step would look like a jump against the others: there the strategy does not apply.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::backend {

struct StampedPose {
  int64_t utime = 0;  // [us]
  Pose2 T_world_base;
};

struct JumpSmoothingConfig {
  // false: the frontend's steps go in as they are (no step or pose replaced); `input` still tells
  // a scanner's stream from a log subsampled by travel for the rest of the backend.
  bool enabled = true;
  int window = 10;                        // preceding steps averaged [steps]
  double speed_ratio = 3.0;               // a step faster than ratio * average speed is a jump
  double min_jump_speed_mps = 0.5;        // ... and faster than this [m/s] (ignores jitter at rest)
  double max_direction_change_rad = 1.0;  // step direction vs average direction, while moving
  double min_moving_speed_mps = 0.1;  // below this average speed, direction is not checked [m/s]
  double max_turn_rate_radps = 3.0;   // a heading rate above this [rad/s] is a jump
  double min_jump_m = 0.3;    // a jump displaces the pose by more than this from the average [m]
  double min_jump_rad = 0.1;  // ... or turns it by more than this [rad]
  // Which input the smoothing applies to (trajectory_prep.hpp): "auto" (a scanner's stream, told
  // from a log subsampled by travel by the median of the last five intervals between poses),
  // "stream" (always smoothed) or "sparse" (never).
  std::string input = "auto";
  // [us] a median interval above this is a log subsampled by travel: the frontend's rule
  // (configs/frontend.yaml, matcher.wide_search_gap_us).
  int64_t sparse_interval_us = 500000;
  // [us] a median interval below this is no scanner's either (none sweeps at 200 Hz): stamps
  // squeezed together (a log restamped a microsecond or a millisecond apart after its clock
  // failed), whose times say nothing of the motion; taken like a log subsampled by travel.
  int64_t min_stream_interval_us = 5000;

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("window", window);
    v("speed_ratio", speed_ratio);
    v("min_jump_speed_mps", min_jump_speed_mps);
    v("max_direction_change_rad", max_direction_change_rad);
    v("min_moving_speed_mps", min_moving_speed_mps);
    v("max_turn_rate_radps", max_turn_rate_radps);
    v("min_jump_m", min_jump_m);
    v("min_jump_rad", min_jump_rad);
    v("input", input);
    v("sparse_interval_us", sparse_interval_us);
    v("min_stream_interval_us", min_stream_interval_us);
  }
};

// An error message when a value is out of range, empty when the config is valid.
// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const JumpSmoothingConfig& config);

struct SmoothedTrajectory {
  std::vector<StampedPose> poses;
  std::vector<int> replaced_steps;  // index k of every step k-1 -> k replaced by the average
  std::vector<int> outliers;        // index k of every pose replaced by its neighbours' average
};

// Returns the trajectory with jumps and outliers replaced; the first pose is kept as is, and the
// last is never an outlier (nothing follows it). Poses must be in time order (equal times are
// treated as a 1 us step).
SmoothedTrajectory smooth_jumps(std::vector<StampedPose> poses, const JumpSmoothingConfig& config);

// smooth_jumps one pose at a time: each raw pose is judged against the smoothed steps before it.
class JumpSmoother {
 public:
  explicit JumpSmoother(JumpSmoothingConfig config) : config_(std::move(config)) {}

  // Starts again at raw pose `raw`, placed at `smoothed` (the first pose, or the first after
  // poses this strategy did not see).
  void restart(const StampedPose& raw, const Pose2& smoothed);
  // Whether raw pose `held` is an outlier that the raw pose after it, `next`, returns from.
  bool is_outlier(const StampedPose& held, const StampedPose& next) const;
  // The outlier `held` replaced by interpolating (by time) between the last raw pose and `next`.
  Pose2 replace_outlier(const StampedPose& held, const StampedPose& next) const;
  // Takes in the next raw pose; returns its smoothed pose. `jump`: its step was replaced.
  Pose2 add(const StampedPose& raw, bool& jump);

 private:
  JumpSmoothingConfig config_;
  std::vector<StampedPose> tail_;  // the last smoothed poses (window + 1)
  StampedPose last_raw_;           // the previous raw pose
};

}  // namespace traverse::backend
