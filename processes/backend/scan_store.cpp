#include "scan_store.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::backend {

std::optional<std::string> validate(const ScanStoreConfig& c) {
  ConfigCheck check;
  check.not_negative("point_spacing_m", c.point_spacing_m);
  check.not_negative("min_range_m", c.min_range_m);
  check.require(c.max_range_m > c.min_range_m, "max_range_m", "must exceed min_range_m");
  return check.problem();
}

std::vector<Eigen::Vector2f> reduce_scan(const PlanarScan& scan, const Pose2& T_base_laser,
                                         const std::function<Pose2(int64_t)>& T_ref_base,
                                         const ScanStoreConfig& config) {
  std::vector<Eigen::Vector2f> kept;
  const int n = static_cast<int>(scan.ranges.size());
  if (n == 0) return kept;
  const double lo = std::max(scan.range_min, config.min_range_m);
  const double hi = std::min(scan.range_max, config.max_range_m);
  const double duration = static_cast<double>(scan.utime_last - scan.utime_first);
  const double spacing2 = config.point_spacing_m * config.point_spacing_m;
  // The motion is evaluated at a few times only (every 1/16 of the sweep) and interpolated between:
  // it is smooth over 20 ms, and an SE(2) interpolation per beam would dominate the cost.
  constexpr int kKnots = 16;
  std::vector<Pose2> knots;
  for (int s = 0; s <= kKnots; ++s) {
    const int64_t t = scan.utime_first + std::llround(duration * s / kKnots);
    knots.push_back(T_ref_base(t) * T_base_laser);
  }
  Eigen::Vector2d last(1e300, 1e300);
  for (int i = 0; i < n; ++i) {
    const double r = scan.ranges[i];
    if (!std::isfinite(r) || r < lo || r > hi) continue;
    const double a = scan.angle_first + i * scan.angle_step;
    const Eigen::Vector2d p_laser(r * std::cos(a), r * std::sin(a));
    const double u = n > 1 ? static_cast<double>(i) * kKnots / (n - 1) : 0.0;
    const int k = std::min(static_cast<int>(u), kKnots - 1);
    const Eigen::Vector2d p = interpolate(knots[k], knots[k + 1], u - k) * p_laser;
    if ((p - last).squaredNorm() < spacing2) continue;
    kept.push_back(p.cast<float>());
    last = p;
  }
  return kept;
}

int ScanStore::add(std::vector<Eigen::Vector2f> points_base) {
  points_base.shrink_to_fit();
  bytes_ += points_base.capacity() * sizeof(Eigen::Vector2f);
  scans_.push_back(std::move(points_base));
  return size() - 1;
}

void ScanStore::append_world(int index, const Pose2& T_world_base,
                             std::vector<Eigen::Vector2d>& out) const {
  for (const auto& p : scans_[index])
    out.push_back(T_world_base * Eigen::Vector2d(p.cast<double>()));
}

std::vector<Eigen::Vector2d> ScanStore::points_d(int index) const {
  std::vector<Eigen::Vector2d> out;
  out.reserve(scans_[index].size());
  for (const auto& p : scans_[index]) out.push_back(p.cast<double>());
  return out;
}

double ScanStore::bytes_per_key_pose() const {
  return scans_.empty() ? 0.0 : static_cast<double>(bytes_) / static_cast<double>(scans_.size());
}

}  // namespace traverse::backend
