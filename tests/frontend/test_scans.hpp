// Helpers shared by the frontend tests: points of a synthetic scan and maps built from them.
#pragma once

#include <Eigen/Core>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "frontend.hpp"
#include "hector/scan_matcher.hpp"
#include "synthetic_scans.hpp"

namespace traverse::frontend::testing {

constexpr int64_t kPeriodUs = 20964;  // 47.7 Hz

// A small, fast setup: 1,800-point sweeps of 300 degrees with 2 mm range noise.
inline synthetic::SweepSpec small_sweep(int64_t utime_first) {
  synthetic::SweepSpec spec;
  spec.n_ranges = 1800;
  spec.angle_step = 300.0 * M_PI / 180.0 / 1799.0;
  spec.utime_first = utime_first;
  spec.noise_sigma_m = 0.002;
  return spec;
}

// End points in the base frame of a full-circle scan from T_world_base (no motion), with
// Gaussian range noise.
inline std::vector<Eigen::Vector2d> static_scan(const synthetic::World& world,
                                                const Pose2& T_world_base, int beams = 1440,
                                                double noise_m = 0.0, unsigned seed = 1,
                                                double max_range_m = 40.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m > 0 ? noise_m : 1.0);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < beams; ++i) {
    const double a = 2.0 * M_PI * i / beams;
    const Eigen::Vector2d d(std::cos(a + T_world_base.theta()), std::sin(a + T_world_base.theta()));
    auto r = synthetic::cast_ray(world, T_world_base.translation(), d, max_range_m);
    if (!r) continue;
    const double range = *r + (noise_m > 0 ? noise(rng) : 0.0);
    points.emplace_back(range * std::cos(a), range * std::sin(a));
  }
  return points;
}

// Every status counter a frontend reports, by name.
inline std::map<std::string, double> counters_of(const Frontend& frontend) {
  std::map<std::string, double> counters;
  frontend.report([&](const std::string& name, double value) { counters[name] = value; });
  return counters;
}

// A map pyramid (map frame = world frame) built from scans taken at the given poses.
inline MapPyramid build_map(const synthetic::World& world, const std::vector<Pose2>& poses,
                            const MapConfig& config = {}) {
  MapPyramid maps(config);
  for (const auto& T : poses) maps.update(T, Eigen::Vector2d::Zero(), static_scan(world, T, 2880));
  return maps;
}

}  // namespace traverse::frontend::testing
