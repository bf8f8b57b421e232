#include "coverage.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>

#include "bounds.hpp"

namespace traverse::annotator {

std::optional<Pose2> truth_at(const std::vector<StampedTruth>& truth, int64_t utime) {
  auto it = std::lower_bound(truth.begin(), truth.end(), utime,
                             [](const StampedTruth& s, int64_t t) { return s.utime < t; });
  if (it == truth.end()) return std::nullopt;
  if (it->utime == utime) return it->T_world_base;
  if (it == truth.begin()) return std::nullopt;
  const StampedTruth& a = *(it - 1);
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(it->utime - a.utime);
  return interpolate(a.T_world_base, it->T_world_base, s);
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double pos = q * static_cast<double>(values.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

CoverageResult evaluate_coverage(const std::vector<KeyRecord>& keys,
                                 const std::vector<StampedTruth>& truth, double local_radius_m,
                                 double published_scale) {
  CoverageResult r;
  if (keys.empty()) return r;
  const auto truth0 = truth_at(truth, keys.front().utime);
  if (!truth0) return r;
  const Pose2 T_align = keys.front().T_world_base * truth0->inverse();
  // Aligned truth per key pose (nullopt outside the ground truth).
  std::vector<std::optional<Pose2>> T_true(keys.size());
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (auto t = truth_at(truth, keys[k].utime)) T_true[k] = T_align * *t;
  }
  int inside = 0, local_inside = 0;
  double se = 0.0, bounds = 0.0;
  std::map<int, LevelFigure> levels;
  std::map<int, double> level_error_sum, level_bound_sum;
  for (std::size_t k = 1; k < keys.size(); ++k) {
    const KeyRecord& key = keys[k];
    if (!T_true[k] || key.bound_m < 0.0) continue;
    const Eigen::Vector2d e = key.T_world_base.translation() - T_true[k]->translation();
    ++r.key_poses;
    se += e.squaredNorm();
    bounds += key.bound_m;
    if (e.norm() <= key.bound_m) ++inside;
    if (key.bound_m > 0.0) {
      r.needed_scale.push_back(e.squaredNorm() / (key.bound_m * key.bound_m) * published_scale);
    }
    const Eigen::Matrix2d c = key.covariance.topLeftCorner<2, 2>();
    if (c.determinant() > 0.0) r.nees.push_back(e.dot(c.inverse() * e));
    // Local: the largest error of a neighbour's position in this key pose's frame.
    if (key.local_bound_m >= 0.0 && local_radius_m > 0.0) {
      double worst = 0.0;
      const Pose2 T_inv_est = key.T_world_base.inverse(), T_inv_true = T_true[k]->inverse();
      for (std::size_t j = 0; j < keys.size(); ++j) {
        if (j == k || !T_true[j]) continue;
        const Eigen::Vector2d d =
            keys[j].T_world_base.translation() - key.T_world_base.translation();
        if (d.norm() > local_radius_m) continue;
        const Eigen::Vector2d rel_est = T_inv_est * keys[j].T_world_base.translation();
        const Eigen::Vector2d rel_true = T_inv_true * T_true[j]->translation();
        worst = std::max(worst, (rel_est - rel_true).norm());
      }
      ++r.local_key_poses;
      if (worst <= key.local_bound_m) ++local_inside;
    }
    // Seed 004's claim: the true error of the points this key pose placed.
    if (key.level >= 0 && !key.points_base.empty()) {
      LevelFigure& f = levels[key.level];
      f.level = key.level;
      ++f.key_poses;
      for (const Eigen::Vector2d& p : key.points_base) {
        level_error_sum[key.level] += (key.T_world_base * p - *T_true[k] * p).norm();
      }
      f.points += static_cast<int64_t>(key.points_base.size());
      level_bound_sum[key.level] += key.bound_m;
    }
  }
  if (r.key_poses == 0) return r;
  r.coverage = static_cast<double>(inside) / r.key_poses;
  r.local_coverage = r.local_key_poses ? static_cast<double>(local_inside) / r.local_key_poses : 0;
  r.position_rmse_m = std::sqrt(se / r.key_poses);
  r.mean_bound_m = bounds / r.key_poses;
  if (!r.nees.empty()) {
    double sum = 0.0;
    for (double v : r.nees) sum += v;
    r.nees_mean = sum / static_cast<double>(r.nees.size());
    r.nees_median = quantile(r.nees, 0.5);
    r.nees_q95 = quantile(r.nees, 0.95);
    r.scale_by_mean = r.nees_mean / 2.0;
    r.scale_by_q95 = r.nees_q95 / kChi2TwoDof95;
  }
  r.scale_by_coverage = quantile(r.needed_scale, 0.95);
  r.levels_increasing = levels.size() >= 2;
  double previous = -1.0;
  for (auto& [level, f] : levels) {
    f.mean_point_error_m = f.points ? level_error_sum[level] / static_cast<double>(f.points) : 0;
    f.mean_bound_m = level_bound_sum[level] / f.key_poses;
    if (f.mean_point_error_m <= previous) r.levels_increasing = false;
    previous = f.mean_point_error_m;
    r.levels.push_back(f);
  }
  return r;
}

}  // namespace traverse::annotator
