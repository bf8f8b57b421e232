// Synthetic trajectories with known answers for the evaluator tests.
#pragma once

#include <cmath>

#include "trajectory.hpp"

namespace traverse::evaluator::test {

// A constant-twist arc (a circle of radius 10 m at 0.4 m/s): SE(2) interpolation between its
// samples is exact, so any error the evaluator reports on it comes from the evaluator.
inline Pose2 circle_pose(double t_s) {
  constexpr double kRadiusM = 10.0, kRateRadPerS = 0.04;
  const double a = kRateRadPerS * t_s;
  return Pose2(kRadiusM * std::cos(a), kRadiusM * std::sin(a), a + M_PI / 2.0);
}

// Samples from `start_us` every `step_us`, `n` poses.
template <class PoseAt>
Trajectory sample(PoseAt pose_at, int64_t start_us, int64_t step_us, int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    const int64_t utime = start_us + i * step_us;
    t.push_back({utime, pose_at(1e-6 * static_cast<double>(utime))});
  }
  return t;
}

// Ground truth at 200 Hz for `seconds` starting at t = 1 s.
inline Trajectory circle_truth(int seconds) {
  return sample(circle_pose, 1'000'000, 5'000, seconds * 200 + 1);
}

}  // namespace traverse::evaluator::test
