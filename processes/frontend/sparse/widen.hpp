// A sparse scan that fits nowhere in the wide search's window is searched again in wider ones.
//
// On a log subsampled by travel without odometry, the wide search looks within
// MatcherConfig::wide_search_linear_window_m of where the log's usual step predicts the scan. A
// step far longer than usual (real CARMEN logs step 2 to 3.3 m where they usually step under one)
// puts the scan outside that window, and the search returns the least bad pose inside it: the
// scan's points then fit the map much worse than the log's scans usually do. That is what this
// wrapper watches: the evidence per point of each sparse match (-1 to 1, as the wide search
// scores it) against the median of the last settled sparse matches'. Below
// sparse_widen_evidence_ratio times that median, the scan is matched again around the same
// prediction in windows sparse_widen_factor, then that squared, ... times wider, up to
// sparse_widen_max_window_m; the first wider match whose evidence reaches the ratio is taken if
// it also beats the narrow one by sparse_lag_margin per point (so a scan of a view the map has
// not seen, which fits nowhere, keeps its narrow match), and its step is marked long
// (Measurement::long_step_m) so that the lag (lag.hpp) does not count it against the log's usual
// steps. Nothing changes for a scan that fits, for a step odometry predicted, nor on a scanner's
// stream; each widening costs the square of its factor in search time.
//
// Measured on tests/carmen/long_step_test.cpp's crafted loop (0.6 m steps, one of 3 m, no
// odometry): the narrow match fits with evidence 0.16-0.21 per point where the log's median is
// 0.91-0.94, the 4 m window's 0.76-0.77 (each of the five ensemble members); the long step comes
// out 0.001 m off, against 2.19 m without widening.
#pragma once

#include <memory>

#include "recent_values.hpp"
#include "two_phase.hpp"

namespace traverse::frontend {

class SparseWiden final : public TwoPhaseFrontend {
 public:
  SparseWiden(std::unique_ptr<TwoPhaseFrontend> inner, const MatcherConfig& config);

  Measurement measure(const Scan& scan) override;
  void integrate(Measurement& measurement) override;
  Measurement rematch(const Measurement& measurement, const SearchArea& area) const override {
    return inner_->rematch(measurement, area);
  }
  double evidence(const Measurement& measurement, const Pose2& T_map_base) const override {
    return inner_->evidence(measurement, T_map_base);
  }
  Pose2 last_pose() const override { return inner_->last_pose(); }
  void begin_tentative() override { inner_->begin_tentative(); }
  void rollback() override { inner_->rollback(); }
  void commit() override { inner_->commit(); }

  bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) override {
    return inner_->add_imu(utime, angular_velocity_imu);
  }
  bool add_odometry(const OdometrySample& odometry) override {
    return inner_->add_odometry(odometry);
  }
  std::size_t map_bytes() const override { return inner_->map_bytes(); }
  void report(const CounterSink& sink) const override;

 private:
  std::unique_ptr<TwoPhaseFrontend> inner_;
  MatcherConfig config_;
  static constexpr std::size_t kRecent = 30;
  // Of the last sparse matches integrated (a scan the lag takes back and integrates elsewhere
  // counts twice: a median of 30 hardly moves for it).
  RecentValues<kRecent> recent_evidence_;
  int64_t scans_widened_ = 0;              // searched again in a wider window
  int64_t scans_moved_ = 0;                // and taken where the wider window put them
};

}  // namespace traverse::frontend
