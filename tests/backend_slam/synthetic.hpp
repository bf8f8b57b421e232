// Synthetic key scans for the backend tests: sweeps ray-cast in the frontend's synthetic worlds
// from a standing platform, converted to the backend's scan type and reduced to points.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "scan_store.hpp"
#include "synthetic_scans.hpp"

namespace traverse::backend::test {

namespace synthetic = traverse::frontend::synthetic;

// The spec of a 360 degree sweep of n beams with max range `range_max_m` and Gaussian range noise.
inline synthetic::SweepSpec full_sweep_spec(int n = 1440, double range_max_m = 20.0,
                                            double noise_m = 0.005) {
  synthetic::SweepSpec spec;
  spec.n_ranges = n;
  spec.angle_first = -M_PI;
  spec.angle_step = 2.0 * M_PI / n;
  spec.range_max = range_max_m;
  spec.noise_sigma_m = noise_m;
  return spec;
}

// A 360 degree sweep of n beams with max range `range_max_m`, as the backend's scan type.
inline PlanarScan sweep(const synthetic::World& world, const Pose2& T_world_base,
                        double range_max_m, std::mt19937& rng, int n = 1440,
                        int64_t utime_first = 0, double noise_m = 0.005) {
  synthetic::SweepSpec spec = full_sweep_spec(n, range_max_m, noise_m);
  spec.utime_first = utime_first;
  return synthetic::make_sweep(
      world, [&](int64_t) { return T_world_base; }, Pose2(), spec, &rng);
}

// Points of a sweep taken at T_world_base, in the base frame, thinned to 5 cm.
inline std::vector<Eigen::Vector2f> key_points(const synthetic::World& world,
                                               const Pose2& T_world_base, double range_max_m,
                                               std::mt19937& rng) {
  ScanStoreConfig config;
  config.max_range_m = range_max_m;
  return reduce_scan(
      sweep(world, T_world_base, range_max_m, rng), Pose2(), [](int64_t) { return Pose2(); },
      config);
}

inline std::vector<Eigen::Vector2d> to_double(const std::vector<Eigen::Vector2f>& p) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& q : p) out.push_back(q.cast<double>());
  return out;
}

// A 30 m corridor, 2.4 m wide, with niches and boxes at irregular places: locally unique.
inline synthetic::World irregular_corridor() {
  synthetic::World w;
  const double xs[] = {-15.0, -11.3, -6.8, -4.1, 0.7, 2.9, 7.6, 9.2, 13.1, 15.0};
  // South wall with niches of varying depth between the listed x positions.
  for (int i = 0; i + 1 < 10; ++i) {
    const double a = xs[i], b = xs[i + 1], depth = 0.3 + 0.15 * (i % 4);
    const double n0 = a + 0.35 * (b - a), n1 = a + 0.35 * (b - a) + 0.9 + 0.2 * (i % 3);
    w.push_back({{a, -1.2}, {n0, -1.2}});
    w.push_back({{n0, -1.2}, {n0, -1.2 - depth}});
    w.push_back({{n0, -1.2 - depth}, {n1, -1.2 - depth}});
    w.push_back({{n1, -1.2 - depth}, {n1, -1.2}});
    w.push_back({{n1, -1.2}, {b, -1.2}});
  }
  w.push_back({{-15.0, 1.2}, {15.0, 1.2}});
  const double boxes[][2] = {{-12.0, 0.6}, {-7.9, 0.75}, {-2.2, 0.5}, {1.6, 0.8},
                             {5.1, 0.55},  {8.4, 0.7},   {11.7, 0.6}};
  for (const auto& b : boxes) {
    const double x = b[0], s = b[1];
    w.push_back({{x, 1.2}, {x, 1.2 - s * 0.6}});
    w.push_back({{x, 1.2 - s * 0.6}, {x + s, 1.2 - s * 0.6}});
    w.push_back({{x + s, 1.2 - s * 0.6}, {x + s, 1.2}});
  }
  return w;
}

// The same corridor with identical niches every 1.5 m on both sides: repeats itself.
inline synthetic::World repetitive_corridor() {
  synthetic::World w;
  for (double x = -15.0; x < 15.0; x += 1.5) {
    for (double side : {-1.0, 1.0}) {
      const double y = side * 1.2, y_back = side * 1.8;
      w.push_back({{x, y}, {x + 0.7, y}});
      w.push_back({{x + 0.7, y}, {x + 0.7, y_back}});
      w.push_back({{x + 0.7, y_back}, {x + 1.5, y_back}});
      w.push_back({{x + 1.5, y_back}, {x + 1.5, y}});
    }
  }
  return w;
}

}  // namespace traverse::backend::test

namespace traverse::backend::test {

// A platform driving laps of an ellipse (3.0 m x 1.5 m radii, 1 m/s) in the frontend's synthetic
// room, one sweep of 1440 beams every 100 ms taken while moving, and a drifting frontend: its
// odometry is 3 % long and turns 0.01 rad per metre too much.
struct Drive {
  std::vector<int64_t> utimes;  // [us] pose times (the last point of each sweep)
  std::vector<Pose2> truth;     // T_world_base at those times
  std::vector<Pose2> input;     // the drifting frontend's T_map_base
  std::vector<PlanarScan> scans;
};

inline Pose2 ellipse_pose(double t_s) {
  // Parameterised by angle at a roughly constant 1 m/s (mean radius 2.25 m).
  const double a = t_s / 2.25;
  const double x = 3.0 * std::cos(a), y = 1.5 * std::sin(a);
  return Pose2(x, y, std::atan2(1.5 * std::cos(a), -3.0 * std::sin(a)));
}

inline Drive drive_ellipse(double duration_s, unsigned seed = 5) {
  std::mt19937 rng(seed);
  Drive d;
  const int64_t period_us = 100000, sweep_us = 20964;
  synthetic::SweepSpec spec = full_sweep_spec();
  spec.duration_us = sweep_us;
  const auto truth_at = [](int64_t t) { return ellipse_pose(1e-6 * static_cast<double>(t)); };
  for (int64_t t0 = 0; 1e-6 * static_cast<double>(t0) < duration_s; t0 += period_us) {
    spec.utime_first = t0;
    PlanarScan scan = synthetic::make_sweep(synthetic::room(), truth_at, Pose2(), spec, &rng);
    const int64_t t = scan.utime_last;
    d.utimes.push_back(t);
    d.truth.push_back(truth_at(t));
    if (d.input.empty()) {
      d.input.push_back(d.truth.back());
    } else {
      const Pose2 step = between(d.truth[d.truth.size() - 2], d.truth.back());
      const double len = step.translation().norm();
      d.input.push_back(d.input.back() *
                        Pose2(1.03 * step.x(), 1.03 * step.y(), step.theta() + 0.01 * len));
    }
    d.scans.push_back(std::move(scan));
  }
  return d;
}

}  // namespace traverse::backend::test
