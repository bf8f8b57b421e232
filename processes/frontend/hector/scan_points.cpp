#include "scan_points.hpp"

#include <cmath>

namespace traverse::frontend {

ScanPoints ScanPointMaker::operator()(const Scan& scan) {
  ScanPoints out;
  const std::size_t n = scan.ranges.size();
  double lo = min_range_m_, hi = max_range_m_;
  if (std::isfinite(scan.range_min) && scan.range_min > lo) lo = scan.range_min;
  if (std::isfinite(scan.range_max) && scan.range_max > 0.0 && scan.range_max < hi)
    hi = scan.range_max;
  const double duration = static_cast<double>(scan.utime_last - scan.utime_first);
  if (!std::isfinite(scan.angle_first) || !std::isfinite(scan.angle_step)) {
    out.invalid = static_cast<int64_t>(n);
    return out;
  }
  if (beam_n_ != n || beam_angle_first_ != scan.angle_first ||
      beam_angle_step_ != scan.angle_step) {
    beam_directions_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double a = scan.angle_first + static_cast<double>(i) * scan.angle_step;
      beam_directions_[i] = T_base_laser_.rotation() * Eigen::Vector2d(std::cos(a), std::sin(a));
    }
    beam_n_ = n;
    beam_angle_first_ = scan.angle_first;
    beam_angle_step_ = scan.angle_step;
  }
  out.points_base.reserve(n);
  out.utimes.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = scan.ranges[i];
    if (!std::isfinite(r) || r <= 0.0 || r < lo || r > hi) {
      ++out.invalid;
      continue;
    }
    out.points_base.push_back(T_base_laser_.translation() + r * beam_directions_[i]);
    const double s = n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 1.0;
    out.utimes.push_back(scan.utime_first + std::llround(s * duration));
  }
  return out;
}

std::vector<Eigen::Vector2d> subsample(const std::vector<Eigen::Vector2d>& points,
                                       double spacing_m) {
  if (spacing_m <= 0.0 || points.empty()) return points;
  std::vector<Eigen::Vector2d> kept{points.front()};
  const double spacing2 = spacing_m * spacing_m;
  for (const auto& p : points) {
    if ((p - kept.back()).squaredNorm() >= spacing2) kept.push_back(p);
  }
  return kept;
}

}  // namespace traverse::frontend
