#include "synthetic_scans.hpp"

#include <cmath>
#include <limits>

namespace traverse::frontend::synthetic {
namespace {

void add_box(World& w, double x0, double y0, double x1, double y1) {
  w.push_back({{x0, y0}, {x1, y0}});
  w.push_back({{x1, y0}, {x1, y1}});
  w.push_back({{x1, y1}, {x0, y1}});
  w.push_back({{x0, y1}, {x0, y0}});
}

}  // namespace

World room() {
  World w;
  // Outer walls with a recess (doorway niche) in the north wall.
  w.push_back({{-5, -4}, {5, -4}});
  w.push_back({{5, -4}, {5, 4}});
  w.push_back({{5, 4}, {1.5, 4}});
  w.push_back({{1.5, 4}, {1.5, 5}});
  w.push_back({{1.5, 5}, {0.5, 5}});
  w.push_back({{0.5, 5}, {0.5, 4}});
  w.push_back({{0.5, 4}, {-5, 4}});
  w.push_back({{-5, 4}, {-5, -4}});
  add_box(w, 2.0, -2.5, 2.6, -1.9);   // pillar
  add_box(w, -3.5, 1.0, -2.5, 2.2);   // cabinet
  add_box(w, -1.0, -3.6, 0.2, -3.2);  // desk against the south wall
  return w;
}

World corridor(double length_m, double width_m) {
  const double h = 0.5 * length_m, y = 0.5 * width_m;
  return {{{-h, -y}, {h, -y}}, {{-h, y}, {h, y}}};
}

World office_block(double length_m) {
  World w;
  const double h = 0.5 * length_m;
  const double door = 0.9, room_depth = 5.0, pitch = 4.0;
  for (double x = -h; x < h; x += pitch) {
    for (double side : {-1.0, 1.0}) {
      const double y_wall = side * 1.2, y_back = side * (1.2 + room_depth);
      // Corridor wall with a door in each room, the partition, and the back wall.
      w.push_back({{x, y_wall}, {x + 1.0, y_wall}});
      w.push_back({{x + 1.0 + door, y_wall}, {x + pitch, y_wall}});
      w.push_back({{x, y_wall}, {x, y_back}});
      w.push_back({{x, y_back}, {x + pitch, y_back}});
      add_box(w, x + 2.2, y_back - side * 1.4 - 0.4, x + 3.4, y_back - side * 1.4 + 0.4);  // desk
    }
  }
  w.push_back({{h, -6.2}, {h, 6.2}});
  w.push_back({{-h, -6.2}, {-h, 6.2}});
  return w;
}

std::optional<double> cast_ray(const World& world, const Eigen::Vector2d& origin,
                               const Eigen::Vector2d& direction, double max_range) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& s : world) {
    // origin + t d = a + u (b - a), t > 0, u in [0, 1].
    const Eigen::Vector2d e = s.b - s.a, w = s.a - origin;
    const double den = direction.x() * (-e.y()) - direction.y() * (-e.x());
    if (std::abs(den) < 1e-12) continue;
    const double t = (w.x() * (-e.y()) - w.y() * (-e.x())) / den;
    const double u = (direction.x() * w.y() - direction.y() * w.x()) / den;
    if (t > 1e-9 && u >= 0.0 && u <= 1.0 && t < best) best = t;
  }
  if (best > max_range) return std::nullopt;
  return best;
}

Scan make_sweep(const World& world, const std::function<Pose2(int64_t)>& T_world_base,
                const Pose2& T_base_laser, const SweepSpec& spec, std::mt19937* rng) {
  Scan scan;
  scan.utime_first = spec.utime_first;
  scan.utime_last = spec.utime_first + spec.duration_us;
  scan.angle_first = spec.angle_first;
  scan.angle_step = spec.angle_step;
  scan.range_min = 0.05;
  scan.range_max = spec.range_max;
  scan.ranges.resize(spec.n_ranges);
  std::normal_distribution<double> noise(0.0, spec.noise_sigma_m);
  for (int i = 0; i < spec.n_ranges; ++i) {
    const double s = spec.n_ranges > 1 ? static_cast<double>(i) / (spec.n_ranges - 1) : 1.0;
    const int64_t t = spec.utime_first + std::llround(s * spec.duration_us);
    const Pose2 T_world_laser = T_world_base(t) * T_base_laser;
    const double a = T_world_laser.theta() + spec.angle_first + i * spec.angle_step;
    const auto r =
        cast_ray(world, T_world_laser.translation(), {std::cos(a), std::sin(a)}, spec.range_max);
    double range = r ? *r : std::numeric_limits<double>::quiet_NaN();
    if (r && rng && spec.noise_sigma_m > 0.0) range += noise(*rng);
    scan.ranges[i] = static_cast<float>(range);
  }
  return scan;
}

}  // namespace traverse::frontend::synthetic
