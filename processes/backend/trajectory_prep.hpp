// Preparing the frontend's dense trajectory for the backend (seed 000, section "pipeline"):
//  1. Jump smoothing. A scan matcher without a backend recovers from accumulated drift at a loop
//     with a discrete jump. Each step between consecutive poses is compared with the average of
//     the preceding steps (as velocities, so uneven scan timing does not matter); a step much
//     longer, or in a clearly different direction, is replaced by that average, and the rest of
//     the trajectory is carried along so it stays continuous. A single bad pose that the next pose
//     returns from (it lies off the path between its neighbours by more than half that path's
//     length) is an outlier, not a jump: it is replaced by interpolating its neighbours, and
//     nothing after it moves. Deviations from the average motion below min_jump_m / min_jump_rad
//     are never jumps: they are scan-matching noise that the backend's own matching handles.
//  2. Key-pose selection: a pose becomes a key pose when enough time has passed since the last
//     one (seed 000 uses three per second), or when the platform has moved or turned enough.
// Poses are T_world_base, times in microseconds.
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
  int window = 10;                        // preceding steps averaged [steps]
  double speed_ratio = 3.0;               // a step faster than ratio * average speed is a jump
  double min_jump_speed_mps = 0.5;        // ... and faster than this [m/s] (ignores jitter at rest)
  double max_direction_change_rad = 1.0;  // step direction vs average direction, while moving
  double min_moving_speed_mps = 0.1;  // below this average speed, direction is not checked [m/s]
  double max_turn_rate_radps = 3.0;   // a heading rate above this [rad/s] is a jump
  // A jump displaces the pose by more than this from the average [m] or turns it by more than
  // this [rad]: only a frontend recovering at a loop; smaller strays are left to the links' scan
  // matching. Measured offline on office-s1, where the frontend strays 0.2 m for a while: 1.33 mm
  // position RMSE with these, 14.3 mm with 5 mm / 5 mrad and 17.1 mm with 5 cm / 0.05 rad.
  double min_jump_m = 0.3;
  double min_jump_rad = 0.1;

  template <class V>
  void visit(V& v) {
    v("window", window);
    v("speed_ratio", speed_ratio);
    v("min_jump_speed_mps", min_jump_speed_mps);
    v("max_direction_change_rad", max_direction_change_rad);
    v("min_moving_speed_mps", min_moving_speed_mps);
    v("max_turn_rate_radps", max_turn_rate_radps);
    v("min_jump_m", min_jump_m);
    v("min_jump_rad", min_jump_rad);
  }
};

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
