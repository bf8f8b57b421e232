// Small synthetic pose graphs for the backend tests, built in code from a known trajectory.
#pragma once

#include <cmath>
#include <random>

#include "pose_graph.hpp"

namespace traverse::backend::testing {

// A random-walk trajectory of n poses with odometry edges and loop closures between poses that
// come within 1.5 m of each other, measurements from the true poses plus Gaussian noise, and
// anisotropic, correlated information matrices. The vertices start at the noisy odometry chain.
inline PoseGraph make_walk_graph(int n, unsigned seed, double noise = 0.02) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> turn(-0.6, 0.6);
  std::vector<Pose2> truth{Pose2()};
  for (int k = 1; k < n; ++k) {
    // Walk inside a 6 m box so that loop closures happen.
    Pose2 step(0.5, 0.0, turn(rng));
    Pose2 next = truth.back() * step;
    if (std::abs(next.x()) > 3.0 || std::abs(next.y()) > 3.0)
      next = truth.back() * Pose2(0.5, 0.0, 2.0);
    truth.push_back(next);
  }
  Eigen::Matrix3d info;
  info << 400.0, 50.0, 10.0, 50.0, 100.0, -20.0, 10.0, -20.0, 900.0;
  auto noisy = [&](const Pose2& z) {
    return Pose2(z.x() + noise * gauss(rng), z.y() + 0.5 * noise * gauss(rng),
                 z.theta() + 0.5 * noise * gauss(rng));
  };
  PoseGraph graph;
  graph.add_vertex(0, truth[0]);
  for (int k = 1; k < n; ++k) {
    const Pose2 z = noisy(between(truth[k - 1], truth[k]));
    graph.add_vertex(k, graph.poses.back() * z);
    graph.edges.push_back({k - 1, k, z, info});
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i + 5 < j; i += 3) {
      if ((truth[i].translation() - truth[j].translation()).norm() < 1.5) {
        graph.edges.push_back({i, j, noisy(between(truth[i], truth[j])), info});
        break;
      }
    }
  }
  return graph;
}

}  // namespace traverse::backend::testing
