// One frontend's scan after its match (Frontend::measure): at once, or on a log subsampled by
// travel one scan behind (MatcherConfig::sparse_lag): a held scan's pose settled once the next
// scan has been matched, and the scan still held at the end of the stream.
#include <algorithm>
#include <cmath>

#include "frontend.hpp"

namespace traverse::frontend {
namespace {

// A step longer than this many times the 90th percentile of the last settled steps is long for
// the log; it loses sparse_lag_long_weight per point at this much beyond.
constexpr double kLongStepFactor = 1.25;
constexpr double kLongStepScaleM = 0.3;

}  // namespace

FrontendResult Frontend::process_own(const Scan& scan) {
  bool by_travel = false;
  FrontendResult result = measure(scan, by_travel);
  if (result.status == ScanStatus::kDropped) return result;
  const bool matched = result.status == ScanStatus::kMatched;
  lagging_ = lagging_ || (by_travel && config_.matcher.sparse_lag);
  if (!lagging_) {
    if (matched) add_to_map(result, points_buffer_);
    T_emitted_last_ = result.T_map_base;
    return result;
  }
  // One scan behind: the held scan is settled with this one's pose, then this one is held, its
  // map update journaled so that settling can move it.
  FrontendResult out;
  out.status = ScanStatus::kHeld;
  out.utime = result.utime;
  if (held_) {
    const int64_t revised = counters_.scans_revised;
    out = settle(*held_, &result);
    if (matched && counters_.scans_revised > revised) {
      // This scan was matched against the held one where it no longer is: again, from its pose.
      const MatchResult m = match_scan_wide(map_, matched_buffer_, {result.T_map_base},
                                            config_.matcher, &out.T_map_base);
      take_match(result, m);
      T_map_base_last_ = m.T_map_base;
      covariance_last_ = m.covariance;
    }
  }
  Held next{result, {}, {}, T_emitted_last_, T_map_base_last_update_};
  if (matched) {
    next.points = points_buffer_;
    next.points_matched = matched_buffer_;
    map_.begin_journal();
    add_to_map(next.result, next.points);
  }
  held_ = std::move(next);
  return out;
}

double Frontend::lag_score(const Held& held, const Pose2& T, const Pose2& T_next) const {
  const int level = std::min(1, map_.levels() - 1);
  const double evidence = pose_evidence(map_.level(level), held.points_matched, T);
  double cost = step_prior_cost(step_prior(config_.matcher, held.T_before), T) +
                step_prior_cost(step_prior(config_.matcher, T), T_next);
  // A step longer than the log's steps usually are (kLongStepFactor times the 90th percentile
  // of the last settled ones) loses sparse_lag_long_weight per point at kLongStepScaleM beyond.
  if (recent_steps_m_.size() >= kRecentSteps / 2) {
    const double limit = kLongStepFactor * recent_steps_m_.percentile(90);
    for (const double length : {between(held.T_before, T).translation().norm(),
                                between(T, T_next).translation().norm()}) {
      const double e = std::max(0.0, length - limit) / kLongStepScaleM;
      cost += config_.matcher.sparse_lag_long_weight * e * e;
    }
  }
  return evidence - cost;
}

FrontendResult Frontend::settle(Held& held, const FrontendResult* next) {
  FrontendResult& r = held.result;
  if (r.status == ScanStatus::kMatched && r.sparse && next != nullptr &&
      next->status == ScanStatus::kMatched && next->sparse) {
    // Where the scan fits best may not be where it was (a room mapped differently on an earlier
    // pass): the pose halfway between the steps around it is a second candidate, matched in a
    // narrow window, and the better of the two by the lag's score is kept.
    const Pose2 mid =
        held.T_before * Pose2::exp(0.5 * between(held.T_before, next->T_map_base).log());
    const Pose2 d = between(mid, r.T_map_base);
    if (d.translation().norm() > config_.matcher.sparse_lag_window_m ||
        std::abs(d.theta()) > config_.matcher.sparse_lag_window_rad) {
      // Compared in the map without the scan itself.
      map_.rollback();
      if (r.map_updated) {
        T_map_base_last_update_ = held.T_last_update_before;
        --counters_.map_updates;
        r.map_updated = false;
      }
      MatcherConfig narrow = config_.matcher;
      narrow.wide_search_linear_window_m = config_.matcher.sparse_lag_window_m;
      narrow.wide_search_angular_window_rad = config_.matcher.sparse_lag_window_rad;
      const MatchResult alt =
          match_scan_wide(map_, held.points_matched, {mid}, narrow, &held.T_before);
      const double own = lag_score(held, r.T_map_base, next->T_map_base);
      const double other = lag_score(held, alt.T_map_base, next->T_map_base);
      if (!poses_agree(alt.T_map_base, r.T_map_base)) {
        const Pose2 T_own = r.T_map_base;
        const bool revise = other > own + config_.matcher.sparse_lag_margin;
        if (revise) {
          ++counters_.scans_revised;
          take_match(r, alt);
        }
        // The candidate not taken is a second place the pose may be: its offset joins the
        // covariance with the weight the wide search's spread would give it (its score, summed
        // over the points, below the other's, in temperatures).
        const double temperature = config_.matcher.wide_search_temperature;
        if (temperature > 0.0) {
          const double gap =
              std::abs(own - other) * static_cast<double>(held.points_matched.size()) / temperature;
          const Pose2& T_other = revise ? T_own : alt.T_map_base;
          Eigen::Vector3d offset;
          offset.head<2>() = T_other.translation() - r.T_map_base.translation();
          offset.z() = wrap_angle(T_other.theta() - r.T_map_base.theta());
          r.covariance += offset * offset.transpose() / (1.0 + std::exp(gap));
        }
      }
      add_to_map(r, held.points);
    }
  }
  map_.end_journal();
  recent_steps_m_.add(between(held.T_before, r.T_map_base).translation().norm());
  T_emitted_last_ = r.T_map_base;
  return r;
}

FrontendResult Frontend::finish_own() {
  if (!held_) return {};
  FrontendResult r = settle(*held_, nullptr);
  held_.reset();
  return r;
}

}  // namespace traverse::frontend
