// Synthetic planar worlds (line segments) and sweeps ray-cast in them while the platform moves,
// every beam at its own time. Used by the tests and the benchmark; not part of the frontend.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "frontend.hpp"
#include "se2.hpp"

namespace traverse::frontend::synthetic {

struct Segment {
  Eigen::Vector2d a, b;  // [m] end points in the world frame
};
using World = std::vector<Segment>;

// A 10 m x 8 m room with a pillar, two boxes and a doorway recess: every direction constrained.
World room();
// Two parallel walls `width_m` apart along x from -length/2 to length/2: nothing constrains x.
World corridor(double length_m, double width_m);
// Offices along both sides of a `length_m` corridor: walls, doors, furniture (for the benchmark).
World office_block(double length_m);

// Range along the ray or nothing within max_range.
std::optional<double> cast_ray(const World& world, const Eigen::Vector2d& origin,
                               const Eigen::Vector2d& direction, double max_range);

struct SweepSpec {
  int n_ranges = 8536;
  double angle_first = -150.0 * M_PI / 180.0;  // [rad] 300 degrees seen, as the simulator
  double angle_step = 300.0 * M_PI / 180.0 / 8535.0;
  int64_t utime_first = 0;      // [us]
  int64_t duration_us = 20964;  // [us] 47.7 Hz
  double range_max = 41.0;      // [m]
  double noise_sigma_m = 0.0;   // [m] Gaussian range noise
};

// Ray-casts one sweep; beam i uses the pose T_world_base(t_i) at its own time.
Scan make_sweep(const World& world, const std::function<Pose2(int64_t)>& T_world_base,
                const Pose2& T_base_laser, const SweepSpec& spec, std::mt19937* rng = nullptr);

}  // namespace traverse::frontend::synthetic
