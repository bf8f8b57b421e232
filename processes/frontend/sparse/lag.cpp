#include "lag.hpp"

#include <algorithm>
#include <cmath>

#include "correlative_search.hpp"
#include "step_prior.hpp"
#include "vote.hpp"

namespace traverse::frontend {
namespace {

// A step longer than this many times the 90th percentile of the last settled steps is long for
// the log; it loses sparse_lag_long_weight per point at this much beyond.
constexpr double kLongStepFactor = 1.25;
constexpr double kLongStepScaleM = 0.3;

}  // namespace

SparseLag::SparseLag(std::unique_ptr<TwoPhaseFrontend> frontend, const MatcherConfig& config)
    : FrontendWrapper(std::move(frontend)), config_(config) {}

FrontendResult SparseLag::process(const Scan& scan) {
  Measurement m = inner_->measure(scan);
  if (!m.result.has_pose()) return m.result;
  lagging_ = lagging_ || m.subsampled_by_travel;
  if (!lagging_) {
    inner_->integrate(m);
    return m.result;
  }
  FrontendResult out;
  out.status = ScanStatus::kHeld;
  out.utime = m.result.utime;
  if (held_) out = settle(std::move(*held_), &m);
  held_ = Held{std::move(m), inner_->last_pose()};
  inner_->begin_tentative();
  inner_->integrate(held_->measurement);
  return out;
}

std::optional<FrontendResult> SparseLag::finish() {
  if (!held_) return std::nullopt;
  const FrontendResult r = settle(std::move(*held_), nullptr);
  held_.reset();
  return r;
}

double SparseLag::score(const Held& held, const Pose2& T, const Measurement& next,
                        const Pose2& T_next) const {
  const double evidence = inner_->evidence(held.measurement, T);
  double cost = step_prior_cost(step_prior(config_, held.T_before), T) +
                step_prior_cost(step_prior(config_, T), T_next);
  if (recent_steps_m_.size() >= kRecentSteps / 2) {
    // A step odometry measured long, or a wider search found long, is not long for the log:
    // its limit grows with it.
    const double usual = recent_steps_m_.percentile(90);
    const auto limit = [&](const Measurement& m) {
      double longest = usual;
      if (m.odometry_step) longest = std::max(longest, m.odometry_step->translation().norm());
      if (m.long_step_m) longest = std::max(longest, *m.long_step_m);
      return kLongStepFactor * longest;
    };
    const std::pair<double, double> steps[] = {
        {between(held.T_before, T).translation().norm(), limit(held.measurement)},
        {between(T, T_next).translation().norm(), limit(next)}};
    for (const auto& [length, limit_m] : steps) {
      const double e = std::max(0.0, length - limit_m) / kLongStepScaleM;
      cost += config_.sparse_lag_long_weight * e * e;
    }
  }
  return evidence - cost;
}

FrontendResult SparseLag::settle(Held held, Measurement* next) {
  Measurement& k = held.measurement;
  bool undone = false, revised = false;
  if (next != nullptr && matched_sparse(k.result) && matched_sparse(next->result)) {
    // Where the scan fits best may not be where it was (a room mapped differently on an earlier
    // pass): the pose halfway between the steps around it is a second candidate, matched in a
    // narrow window, and the better of the two by the lag's score is kept.
    // With wheel odometry the second candidate is where odometry's step puts the scan, not
    // halfway: one step of a pair may be much longer than the other.
    const Pose2& T_next = next->result.T_map_base;
    const Pose2 mid = k.odometry_step ? held.T_before * *k.odometry_step
                                      : interpolate(held.T_before, T_next, 0.5);
    const Pose2 d = between(mid, k.result.T_map_base);
    if (d.translation().norm() > config_.sparse_lag_window_m ||
        std::abs(d.theta()) > config_.sparse_lag_window_rad) {
      inner_->rollback();  // compared in the map without the scan itself
      undone = true;
      const Measurement alt = inner_->rematch(
          k, {mid, config_.sparse_lag_window_m, config_.sparse_lag_window_rad, held.T_before});
      const double own = score(held, k.result.T_map_base, *next, T_next);
      const double other = score(held, alt.result.T_map_base, *next, T_next);
      if (!poses_agree(alt.result.T_map_base, k.result.T_map_base)) {
        const Pose2 T_own = k.result.T_map_base;
        revised = other > own + config_.sparse_lag_margin;
        if (revised) {
          ++scans_revised_;
          k = alt;
        }
        // The candidate not taken is a second place the pose may be: its offset joins the
        // covariance with the weight the wide search's spread would give it (its score, summed
        // over the points, below the other's, in temperatures).
        const double temperature = config_.wide_search_temperature;
        if (temperature > 0.0) {
          const double gap =
              std::abs(own - other) * static_cast<double>(k.points_matched.size()) / temperature;
          const Pose2& T_other = revised ? T_own : alt.result.T_map_base;
          correlative::ScoreSpread spread;
          spread.add(1.0, Eigen::Vector3d::Zero());
          spread.add(std::exp(-gap),
                     Eigen::Vector3d(T_other.x() - k.result.T_map_base.x(),
                                     T_other.y() - k.result.T_map_base.y(),
                                     wrap_angle(T_other.theta() - k.result.T_map_base.theta())));
          k.result.covariance += spread.about_chosen();
        }
      }
      inner_->integrate(k);
    }
  }
  if (!undone) inner_->commit();
  recent_steps_m_.add(between(held.T_before, k.result.T_map_base).translation().norm());
  if (revised) {
    // The next scan was matched against this one where it no longer is: again, from its pose.
    *next = inner_->rematch(*next, {next->result.T_map_base, config_.wide_search_linear_window_m,
                                    config_.wide_search_angular_window_rad, k.result.T_map_base});
  }
  return k.result;
}

void SparseLag::report(const CounterSink& sink) const {
  inner_->report(sink);
  sink("scans_revised", static_cast<double>(scans_revised_));
}

}  // namespace traverse::frontend
