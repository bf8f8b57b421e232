#include "widen.hpp"

namespace traverse::frontend {

SparseWiden::SparseWiden(std::unique_ptr<TwoPhaseFrontend> inner, const MatcherConfig& config)
    : inner_(std::move(inner)), config_(config) {}

Measurement SparseWiden::measure(const Scan& scan) {
  Measurement m = inner_->measure(scan);
  if (!matched_sparse(m.result) || !m.subsampled_by_travel || m.odometry_step ||
      recent_evidence_.size() < kRecent / 2) {
    return m;
  }
  const double usual = recent_evidence_.percentile(50);
  const double own = inner_->evidence(m, m.result.T_map_base);
  if (own >= config_.sparse_widen_evidence_ratio * usual) return m;
  ++scans_widened_;
  const Pose2 T_centre = m.result.diagnostics ? m.result.diagnostics->T_map_base_predicted
                                              : m.result.T_map_base;
  for (double window = config_.wide_search_linear_window_m * config_.sparse_widen_factor;
       window <= config_.sparse_widen_max_window_m + 1e-9;
       window *= config_.sparse_widen_factor) {
    Measurement wide = inner_->rematch(
        m, {T_centre, window, config_.wide_search_angular_window_rad, inner_->last_pose()});
    const double e = inner_->evidence(wide, wide.result.T_map_base);
    if (e < config_.sparse_widen_evidence_ratio * usual) continue;
    if (e < own + config_.sparse_lag_margin) break;
    ++scans_moved_;
    wide.long_step_m = between(inner_->last_pose(), wide.result.T_map_base).translation().norm();
    return wide;
  }
  return m;
}

void SparseWiden::integrate(Measurement& m) {
  if (matched_sparse(m.result) && m.subsampled_by_travel)
    recent_evidence_.add(inner_->evidence(m, m.result.T_map_base));
  inner_->integrate(m);
}

void SparseWiden::report(const CounterSink& sink) const {
  inner_->report(sink);
  sink("scans_widened", static_cast<double>(scans_widened_));
  sink("scans_moved_by_widening", static_cast<double>(scans_moved_));
}

}  // namespace traverse::frontend
