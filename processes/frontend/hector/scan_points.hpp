// A sweep's valid readings as points in the base frame, each with its own time, and the subset
// the matcher uses.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "frontend.hpp"
#include "se2.hpp"

namespace traverse::frontend {

struct ScanPoints {
  std::vector<Eigen::Vector2d> points_base;  // [m] base frame, at each reading's own time
  std::vector<int64_t> utimes;               // [us] one per point
  int64_t invalid = 0;  // readings that are NaN, zero, negative or out of range
};

// Turns readings into points, beam directions computed once per scan geometry (it rarely
// changes). A reading is valid when finite, positive, and inside both [min_range_m, max_range_m]
// and the scan's own [range_min, range_max]; reading i is taken at utime_first + i (utime_last
// - utime_first) / (n - 1).
class ScanPointMaker {
 public:
  ScanPointMaker(const Pose2& T_base_laser, double min_range_m, double max_range_m)
      : T_base_laser_(T_base_laser), min_range_m_(min_range_m), max_range_m_(max_range_m) {}
  ScanPoints operator()(const Scan& scan);

 private:
  Pose2 T_base_laser_;
  double min_range_m_, max_range_m_;
  std::size_t beam_n_ = 0;
  double beam_angle_first_ = 0.0, beam_angle_step_ = 0.0;
  std::vector<Eigen::Vector2d> beam_directions_;  // base frame
};

// Points closer than spacing_m to the previously kept one along the scan are left out (0: all).
std::vector<Eigen::Vector2d> subsample(const std::vector<Eigen::Vector2d>& points,
                                       double spacing_m);

}  // namespace traverse::frontend
