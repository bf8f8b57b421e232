// Timestamped planar trajectories and their matching by time: the reference (simulator ground
// truth at 200 Hz, or sparse reference poses, one per scan) is interpolated on SE(2) at each
// estimate's time. Nothing is extrapolated beyond the reference's span, and nothing is
// interpolated across a reference gap longer than a threshold, so that a missing stretch of the
// reference never invents errors: such estimates are counted as unmatched.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "se2.hpp"

namespace traverse::evaluator {

struct StampedPose {
  int64_t utime = 0;  // [us] time the pose is valid at
  Pose2 pose;         // T_world_base (reference) or T_map_base (estimate)
  // Of (x [m], y [m], theta [rad]) in the pose's parent frame, as the pose message carried it;
  // zero when unknown (ground truth, key poses whose marginals are correlated with each other).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

using Trajectory = std::vector<StampedPose>;

// Sorts by time and keeps the first of several poses with the same time.
void sort_unique(Trajectory& trajectory);

// The pose of `trajectory` (sorted by time) nearest `utime`, if one lies within `tolerance_us`.
const StampedPose* pose_at(const Trajectory& trajectory, int64_t utime, int64_t tolerance_us);

struct MatchConfig {
  // [us] longest reference gap interpolated across (ground truth comes every 5 ms).
  int64_t max_reference_gap_us = 500'000;
  // [us] an estimate this close to a reference sample is matched even inside a longer gap: sparse
  // references (one pose per CARMEN scan) are stamped at another instant of the same scan.
  int64_t edge_tolerance_us = 50'000;
};

// Answers "where was the reference at time t": a sorted reference, its cumulative path length.
class ReferenceInterpolator {
 public:
  // `reference` must be sorted with unique times (sort_unique).
  explicit ReferenceInterpolator(const Trajectory& reference, MatchConfig config = {});

  struct Sample {
    Pose2 pose;           // interpolated reference pose
    double travel_m = 0;  // [m] path length of the reference from its first pose to this time
  };
  // Interpolated pose at `utime`, or nullopt outside the span or inside a too long gap.
  std::optional<Sample> at(int64_t utime) const;

 private:
  const Trajectory& reference_;
  MatchConfig config_;
  std::vector<double> travel_m_;  // [m] cumulative path length at each reference pose
};

}  // namespace traverse::evaluator
