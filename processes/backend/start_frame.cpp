#include "start_frame.hpp"

#include <algorithm>
#include <cmath>

#include "config.hpp"
#include "median.hpp"

namespace traverse::backend {

std::optional<std::string> validate(const StartFrameConfig& c) {
  ConfigCheck check;
  check.in_range("early_travel_m", c.early_travel_m, 0.0, 1e3);
  check.in_range("min_travel_m", c.min_travel_m, c.early_travel_m, 1e3);
  check.in_range("min_early_share", c.min_early_share, 0.0, 1.0);
  check.in_range("max_travel_m", c.max_travel_m, c.min_travel_m, 1e3);
  check.in_range("max_distance_m", c.max_distance_m, 0.0, 1e3);
  check.in_range("max_turn_rad", c.max_turn_rad, 0.0, 3.2);
  check.in_range("min_response", c.min_response, 0.0, 1.0);
  check.in_range("min_matches", c.min_matches, 1, 1000);
  check.in_range("min_heading_rad", c.min_heading_rad, 0.0, 0.5);
  check.in_range("min_sigmas", c.min_sigmas, 0.0, 100.0);
  return check.problem();
}

void StartFrame::update(const std::vector<Pose2>& key_poses, const std::vector<double>& travel_m,
                        const ScanStore& scans, const CorrelativeMatcher& matcher,
                        const ScanRefiner& refiner) {
  if (!config_.enabled || key_poses.empty()) return;
  const Pose2& first = key_poses.front();
  if (!measured_ && travel_m.back() > config_.max_travel_m) {
    measured_ = true;
    std::vector<Eigen::Vector2d> reference;
    scans.append_world(0, first, reference);
    for (int k = 1; k < static_cast<int>(key_poses.size()) && k < scans.size(); ++k) {
      if (travel_m[k] > config_.max_travel_m) continue;
      const Pose2& T = key_poses[k];
      if ((T.translation() - first.translation()).norm() > config_.max_distance_m) continue;
      if (std::abs(wrap_angle(T.theta() - first.theta())) > config_.max_turn_rad) continue;
      const std::vector<Eigen::Vector2d> query = scans.points_d(k);
      const MatchResult m = matcher.match(reference, query, T);
      if (!m.valid || m.raw_response < config_.min_response) continue;
      const RefineResult r = refiner.refine(reference, query, m.T_world_query);
      if (!r.valid) continue;
      matched_.push_back({k, travel_m[k], wrap_angle(r.T_world_query.theta() - first.theta())});
    }
  }
  heading_.reset();
  std::vector<double> early, late;
  for (const Match& m : matched_) {
    const double h = wrap_angle(key_poses[m.key].theta() - first.theta() - m.heading_rad);
    if (m.travel_m <= config_.early_travel_m) early.push_back(h);
    if (m.travel_m >= config_.min_travel_m) late.push_back(h);
  }
  if (late.empty()) return;
  estimate_ = *median(late);
  early_estimate_ = median(early).value_or(0.0);
  std::vector<double> deviation;
  for (double v : late) deviation.push_back(std::abs(v - estimate_));
  const double mad = *median(deviation);
  // A turn the grid gave the map at once (its first scans), not a drift that goes on.
  const bool at_once = !early.empty() && early_estimate_ * estimate_ > 0.0 &&
                       std::abs(early_estimate_) >= config_.min_early_share * std::abs(estimate_);
  if (static_cast<int>(late.size()) >= config_.min_matches &&
      std::abs(estimate_) >= config_.min_heading_rad &&
      std::abs(estimate_) >= config_.min_sigmas * mad && at_once) {
    heading_ = estimate_;
  }
}

Pose2 StartFrame::published(const Pose2& T_world_base, const Pose2& T_world_first) const {
  if (!heading_) return T_world_base;
  // A turn by -h about the first key pose: positions about its position, headings by -h.
  return T_world_first * Pose2(0.0, 0.0, -*heading_) * T_world_first.inverse() * T_world_base;
}

}  // namespace traverse::backend
