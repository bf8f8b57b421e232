// Preparing the frontend's trajectory for the backend (seed 000, section "pipeline"), one pose at
// a time:
//  1. Poses out of time order are dropped (counted): the backend's times must increase.
//  2. The kind of input is told from the intervals between poses: a scanner's stream (tens of
//     poses per second) or a log subsampled by travel (a scan kept every metre or half radian,
//     seconds apart; the CARMEN sets), by the last five intervals: a stream has all of them
//     within [min_stream_interval_us, sparse_interval_us], so stamps squeezed together where a
//     log's clock failed do not pass for a fast scanner (stricter than the frontend's median, which
//     took Kummerle's full-rate intel for a stream half the time). Each kind has its own jump
//     handling: a scanner's stream gets seed 000's jump smoothing (jump_smoothing.hpp); on a log
//     subsampled by travel, where real steps of 0.5-1.8 m and 0.5 rad come seconds apart, a step
//     says nothing about the next one, so the poses pass unchanged and the pose graph weighs each
//     step by the frontend's covariance.
//  3. Key-pose selection: a pose becomes a key pose when enough time has passed since the last
//     one (seed 000 uses three per second), or when the platform has moved or turned enough.
// Poses are T_world_base (the prepared frame, which starts equal to the frontend's map frame),
// times in microseconds.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "jump_smoothing.hpp"
#include "se2.hpp"

namespace traverse::backend {

struct FrontendPose {
  int64_t utime = 0;  // [us]
  Pose2 T_map_base;   // the frontend's pose
  // The frontend's covariance of (x [m], y [m], theta [rad]) in its map frame: m^2, m rad, rad^2
  // (zero: unknown).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

struct PreparedPose {
  int64_t utime = 0;      // [us]
  Pose2 T_world_base;     // prepared (smoothed where the strategy smooths)
  FrontendPose frontend;  // the frontend's pose (an outlier replaced by its neighbours')
  double travel_m = 0.0;  // [m] distance along the prepared trajectory from its first pose
  bool sparse = false;    // taken as a log subsampled by travel
  // Paced as a scanner's stream at large: the mean of the last 51 intervals between
  // min_stream_interval_us and 0.5 s, a pause or a burst in it aside; a log subsampled by travel
  // (seconds apart) or whose stamps are squeezed together is not.
  bool paced = false;
};

struct TrajectoryPrepCounters {
  long poses = 0;              // frontend poses given
  long out_of_order = 0;       // ... dropped: not later than the pose before
  long sparse_poses = 0;       // prepared as a log subsampled by travel
  long jumps_smoothed = 0;     // frontend steps replaced by the average (a scanner's stream)
  long outliers_replaced = 0;  // single poses replaced by their neighbours' average (same)
};

class TrajectoryPrep {
 public:
  // The config must pass validate().
  explicit TrajectoryPrep(JumpSmoothingConfig config);

  // Takes in a frontend pose; returns the pose before it, prepared: a pose can be told from an
  // outlier only once the next one is known.
  std::optional<PreparedPose> add(const FrontendPose& pose);
  // End of data: the held pose, prepared.
  std::optional<PreparedPose> finish();

  const TrajectoryPrepCounters& counters() const { return counters_; }
  // Goes on after `last` as if it had been the last pose prepared (a backend resumed from its
  // saved state, backend_state.hpp): the next pose is prepared against it, from its frame.
  void resume(const PreparedPose& last, const TrajectoryPrepCounters& counters);

 private:
  // Whether the poses are taken as a log subsampled by travel (after the newest interval).
  bool sparse() const;
  // Whether they are paced as a scanner's stream at large (PreparedPose::paced).
  bool paced() const;
  PreparedPose prepare(FrontendPose pose, const std::optional<FrontendPose>& next);

  JumpSmoothingConfig config_;
  JumpSmoother smoother_;
  TrajectoryPrepCounters counters_;
  std::optional<FrontendPose> held_;  // the newest pose, not yet prepared
  std::optional<PreparedPose> last_;  // the last prepared pose
  // The last intervals between poses given [us]: sparse() reads the newest five, paced() all 51.
  std::deque<int64_t> intervals_us_;
  int64_t pace_sum_us_ = 0;  // their sum, each held to 10^6 s [us]
};

struct KeyPoseConfig {
  int64_t interval_us = 333333;  // a key pose at least this often [us]
  double distance_m = 0.0;       // ... or after this travelled distance [m]; 0: not by distance
  double angle_rad = 0.0;        // ... or after this turned angle [rad]; 0: not by angle

  template <class V>
  void visit(V& v) {
    v("interval_us", interval_us);
    v("distance_m", distance_m);
    v("angle_rad", angle_rad);
  }
};

std::optional<std::string> validate(const KeyPoseConfig& config);

// Indices of the key poses: the first pose, then every pose at which one of the enabled criteria
// is reached since the last key pose (distance and angle accumulated along the trajectory).
std::vector<int> select_key_poses(const std::vector<StampedPose>& poses,
                                  const KeyPoseConfig& config);

}  // namespace traverse::backend
