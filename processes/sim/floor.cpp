#include "floor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "rng.hpp"

namespace traverse::sim {

double smootherstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * t * (t * (6.0 * t - 15.0) + 10.0);
}

namespace {

Eigen::Vector2d xy(const std::vector<double>& v, const char* what) {
  if (v.size() != 2) throw std::runtime_error(std::string("floor: ") + what + " needs [x, y]");
  return {v[0], v[1]};
}

// Along-segment coordinate u in [0, L] and signed distance across it of p.
struct SegmentFrame {
  Eigen::Vector2d a, dir;
  double length;
  void at(const Eigen::Vector2d& p, double& u, double& across) const {
    const Eigen::Vector2d q = p - a;
    u = q.dot(dir);
    across = dir.x() * q.y() - dir.y() * q.x();
  }
};

SegmentFrame frame_of(const std::vector<double>& a, const std::vector<double>& b,
                      const char* what) {
  const Eigen::Vector2d pa = xy(a, what), pb = xy(b, what);
  const double len = (pb - pa).norm();
  if (len < 1e-6) throw std::runtime_error(std::string("floor: ") + what + " has no length");
  return {pa, (pb - pa) / len, len};
}

}  // namespace

FloorModel::FloorModel(const FloorSpec& spec, const FloorEffect& effect, double half_track_m,
                       uint64_t seed)
    : spec_(spec), effect_(effect), half_track_m_(half_track_m), seed_(seed) {
  for (const auto& t : spec_.thresholds) {
    frame_of(t.a, t.b, "threshold");
    if (t.height < 0 || t.width < 0 || t.bevel <= 0)
      throw std::runtime_error("floor: threshold needs height, width >= 0 and bevel > 0");
  }
  for (const auto& r : spec_.ramps) {
    frame_of(r.a, r.b, "ramp");
    if (r.width <= 0 || std::abs(r.slope_rad) > 0.2)
      throw std::runtime_error("floor: ramp needs width > 0 and |slope_rad| <= 0.2");
  }
  if (spec_.tile_size_m < 0) throw std::runtime_error("floor: tile_size_m must be >= 0");
}

double FloorModel::tile_offset(int64_t i, int64_t j) const {
  // One normal draw per tile from a generator keyed by the tile: the same tile always has the
  // same offset, whatever order tiles are asked for in.
  const uint64_t key = static_cast<uint64_t>(i) * 0x9E3779B97F4A7C15ULL ^
                       static_cast<uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL;
  Rng rng(seed_, key);
  const double h = rng.normal(effect_.tile_step_sigma_m);
  return std::clamp(h, -effect_.tile_step_max_m, effect_.tile_step_max_m);
}

double FloorModel::tiles(const Eigen::Vector2d& p) const {
  const double size = spec_.tile_size_m;
  if (size <= 0.0 || effect_.tile_step_sigma_m <= 0.0) return 0.0;
  // Per axis: the tile index and, near a joint, the neighbour and the blend weight towards it.
  auto axis = [&](double x, int64_t& i0, int64_t& i1, double& w1) {
    const double u = x / size;
    const double fl = std::floor(u);
    i0 = i1 = static_cast<int64_t>(fl);
    w1 = 0.0;
    const double from_low = (u - fl) * size, from_high = size - from_low;
    const double half = 0.5 * effect_.joint_ramp_m;
    if (from_low < half) {
      i1 = i0 - 1;
      w1 = 1.0 - smootherstep(0.5 + from_low / effect_.joint_ramp_m);
    } else if (from_high < half) {
      i1 = i0 + 1;
      w1 = smootherstep(0.5 - from_high / effect_.joint_ramp_m);
    }
  };
  int64_t x0, x1, y0, y1;
  double wx, wy;
  axis(p.x(), x0, x1, wx);
  axis(p.y(), y0, y1, wy);
  double h = (1 - wx) * (1 - wy) * tile_offset(x0, y0);
  if (wx > 0) h += wx * (1 - wy) * tile_offset(x1, y0);
  if (wy > 0) h += (1 - wx) * wy * tile_offset(x0, y1);
  if (wx > 0 && wy > 0) h += wx * wy * tile_offset(x1, y1);
  return h;
}

double FloorModel::height(const Eigen::Vector2d& p) const {
  double h = tiles(p);
  for (const auto& t : spec_.thresholds) {
    const SegmentFrame f = frame_of(t.a, t.b, "threshold");
    double u, across;
    f.at(p, u, across);
    if (u < -0.05 || u > f.length + 0.05) continue;  // a strip a little wider than the doorway
    const double d = std::abs(across) - 0.5 * t.width;
    h += t.height * (1.0 - smootherstep(d / t.bevel));
  }
  for (const auto& r : spec_.ramps) {
    const SegmentFrame f = frame_of(r.a, r.b, "ramp");
    double u, across;
    f.at(p, u, across);
    if (u <= 0.0 || u >= f.length) continue;
    // sin^2 hump of length L whose steepest slope is slope_rad: height slope * L / pi.
    const double s = std::sin(std::numbers::pi * u / f.length);
    const double fade = 1.0 - smootherstep((std::abs(across) - 0.5 * r.width) / 0.5);
    h += std::tan(r.slope_rad) * f.length / std::numbers::pi * s * s * fade;
  }
  return h;
}

CartAttitude FloorModel::attitude(const Pose2& T_world_base) const {
  const double hw = 0.5 * effect_.wheelbase_m, ht = half_track_m_;
  auto at = [&](double x, double y) { return height(T_world_base * Eigen::Vector2d(x, y)); };
  const double fl = at(hw, ht), fr = at(hw, -ht), rl = at(-hw, ht), rr = at(-hw, -ht);
  CartAttitude a;
  a.z = 0.25 * (fl + fr + rl + rr);
  // Nose up (front higher) is a negative pitch about y; left side up a positive roll about x.
  a.pitch = std::atan2(0.5 * (rl + rr) - 0.5 * (fl + fr), effect_.wheelbase_m);
  a.roll = std::atan2(0.5 * (fl + rl) - 0.5 * (fr + rr), 2.0 * ht);
  return a;
}

}  // namespace traverse::sim
