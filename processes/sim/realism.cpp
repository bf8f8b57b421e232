#include "realism.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace traverse::sim {

void ScanStats::add(const std::vector<float>& ranges, double angle_first, double angle_step,
                    const RealismConfig& c) {
  const int n = static_cast<int>(ranges.size());
  ++scans;
  beams += n;
  std::vector<char> ok(n);
  std::vector<Eigen::Vector2d> p(n);
  for (int i = 0; i < n; ++i) {
    const double r = ranges[i];
    ok[i] = std::isfinite(r) && r >= c.min_range_m && r <= c.max_range_m;
    returns += ok[i];
    const double a = angle_first + i * angle_step;
    p[i] = ok[i] ? Eigen::Vector2d(r * std::cos(a), r * std::sin(a)) : Eigen::Vector2d::Zero();
  }
  // Steps between neighbouring ranges (0 where either has no return).
  std::vector<double> d(n, 0.0);
  for (int i = 0; i + 1 < n; ++i) d[i] = ok[i] && ok[i + 1] ? ranges[i + 1] - ranges[i] : 0.0;
  auto has = [&](int i) { return i >= 0 && i + 1 < n && ok[i] && ok[i + 1]; };
  auto step = [&](int i) { return has(i) ? d[i] : 0.0; };
  // A depth jump: a long step unlike a neighbouring one (a wall seen at a grazing angle has long
  // steps too, but alike).
  for (int i = 0; i + 1 < n; ++i) {
    if (!has(i) || std::abs(d[i]) <= c.jump_m) continue;
    const bool unlike_before = has(i - 1) && std::abs(d[i] - d[i - 1]) > c.jump_m;
    const bool unlike_after = has(i + 1) && std::abs(d[i] - d[i + 1]) > c.jump_m;
    jumps += unlike_before || unlike_after || (!has(i - 1) && !has(i + 1));
  }
  for (int i = 1; i + 1 < n; ++i) {
    if (!ok[i - 1] || !ok[i] || !ok[i + 1]) continue;
    const double a = d[i - 1], b = d[i];  // into and out of beam i
    // A spike: off both neighbours the same way.
    if (std::abs(a) > c.jump_m && std::abs(b) > c.jump_m && (a > 0) != (b > 0)) ++outliers;
    // A mixed pixel: between the two sides of a jump, which are locally flat in range.
    if (std::abs(a + b) > c.jump_m && std::abs(a) > c.mixed_margin_m &&
        std::abs(b) > c.mixed_margin_m && (a > 0) == (b > 0) &&
        std::abs(step(i - 2)) < c.mixed_margin_m && std::abs(step(i + 1)) < c.mixed_margin_m)
      ++mixed;
  }
  // Residual of beam i against the line through its neighbours i-2, i-1, i+1, i+2.
  for (int i = 2; i + 2 < n; ++i) {
    bool smooth = true;
    for (int j = i - 2; j <= i + 2 && smooth; ++j)
      smooth = ok[j] && (j == i - 2 || std::abs(d[j - 1]) <= c.jump_m);
    if (!smooth) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int j : {i - 2, i - 1, i + 1, i + 2}) mean += p[j];
    mean /= 4.0;
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (int j : {i - 2, i - 1, i + 1, i + 2}) cov += (p[j] - mean) * (p[j] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    const Eigen::Vector2d normal = eig.eigenvectors().col(0);  // smallest eigenvalue
    residuals.push_back(normal.dot(p[i] - mean));
  }
}

RealismSummary summarize(const ScanStats& s) {
  RealismSummary out;
  out.scans = s.scans;
  if (s.scans == 0) return out;
  out.returns_per_scan = static_cast<double>(s.returns) / s.scans;
  out.return_fraction = s.beams > 0 ? static_cast<double>(s.returns) / s.beams : 0.0;
  out.jumps_per_scan = static_cast<double>(s.jumps) / s.scans;
  out.mixed_per_jump = s.jumps > 0 ? static_cast<double>(s.mixed) / s.jumps : 0.0;
  out.outlier_fraction =
      s.returns > 0 ? static_cast<double>(s.outliers + s.mixed) / s.returns : 0.0;
  out.outliers_per_jump = s.jumps > 0 ? static_cast<double>(s.outliers + s.mixed) / s.jumps : 0.0;
  out.residual_count = static_cast<int64_t>(s.residuals.size());
  if (s.residuals.empty()) return out;
  std::vector<double> abs_res;
  abs_res.reserve(s.residuals.size());
  for (double r : s.residuals) abs_res.push_back(std::abs(r));
  auto quantile = [&](double q) {
    std::vector<double> v = abs_res;
    const auto k = static_cast<std::size_t>(q * (v.size() - 1));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[k];
  };
  out.sigma_m = 1.4826 * quantile(0.5);
  out.p95_m = quantile(0.95);
  int64_t tail = 0;
  for (double a : abs_res) tail += a > 3.0 * out.sigma_m;
  out.tail_fraction = static_cast<double>(tail) / abs_res.size();
  return out;
}

}  // namespace traverse::sim
