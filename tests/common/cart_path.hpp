// A wheeled cart's path and the path a frontend tracks when the horizontal scanner is turned on
// the cart (common/extrinsic_yaw.hpp), for the tests of the boresight estimate and its users.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "se2.hpp"

namespace traverse::test {

// Straight legs joined by arcs both ways and a weave of a few cm, the heading along the path
// (what the estimate relies on), sampled every `step_m`; a point `lever_m` ahead of the axle is
// what is tracked.
inline std::vector<Pose2> cart_path(double step_m, double lever_m) {
  std::vector<Pose2> path;
  Pose2 T;
  const auto drive = [&](double length_m, double curvature) {
    for (double s = 0.0; s < length_m; s += step_m) {
      // A slight weave on straight legs: the heading follows the path.
      const double k = curvature + (curvature == 0.0 ? 0.02 * std::sin(0.8 * s) : 0.0);
      T = T * Pose2::exp(Eigen::Vector3d(step_m, 0.0, k * step_m));
      path.push_back(T * Pose2(lever_m, 0.0, 0.0));
    }
  };
  for (int lap = 0; lap < 2; ++lap) {
    drive(12.0, 0.0);
    drive(2.0, 1.0 / 1.5);  // a left corner
    drive(10.0, 0.0);
    drive(3.0, -1.0 / 2.0);  // a right corner
    drive(15.0, 0.0);
  }
  return path;
}

// The poses a frontend tracking bhat (the base turned by delta) gives for a base path, in a map
// frame at the path's first pose: T_map_bhat = Rot(-delta) T_map_base Rot(delta), with noise of
// `noise_m` on positions and a tenth of it [rad] on headings.
inline std::vector<Pose2> as_tracked(const std::vector<Pose2>& path, double delta, double noise_m,
                                     unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise_m);
  std::vector<Pose2> tracked;
  const Pose2 R(0.0, 0.0, delta);
  const Pose2 T0_inverse = path.front().inverse();
  for (const Pose2& T : path) {
    const Pose2 E = R.inverse() * (T0_inverse * T) * R;
    tracked.emplace_back(E.x() + n(rng), E.y() + n(rng), E.theta() + 0.1 * n(rng));
  }
  return tracked;
}

}  // namespace traverse::test
