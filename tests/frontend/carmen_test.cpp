// The frontend on the four real CARMEN logs (SICK, 180 beams, no odometry, no IMU), configured by
// configs/frontend.yaml, compared with each log's corrected reference trajectory: relative pose
// error over 1 m and 10 m of travel, and the largest jump (step of the estimate beyond the
// reference's step), and each step's error against the reported covariances: computed by the
// evaluator's library, so the same figures scripts/eval-carmen.sh NAME --stages frontend reports
// (rpe_1m_m, rpe_10m_m, max_jump_m, step_nees_median, step_outside_99_fraction).
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "carmen_log.hpp"
#include "carmen_node.hpp"
#include "config.hpp"
#include "evaluator.hpp"
#include "frontend.hpp"
#include "scan_message.hpp"

namespace traverse::frontend {
namespace {

struct Metrics {
  int scans = 0;
  int predicted = 0;
  int searched = 0;
  double widened = 0, moved_by_widening = 0;  // sparse/widen.hpp's counters
  evaluator::Evaluation ev;  // as traverse-evaluator computes it (rpe, max_jump, step NEES)
};

Metrics run_log(const std::string& path) {
  carmen::Reader reader(path);
  EXPECT_TRUE(reader.good()) << path;
  FrontendConfig config;
  load_config("configs/frontend.yaml", config);
  const std::unique_ptr<Frontend> frontend = make_frontend(config);
  evaluator::Trajectory ref, est;
  Metrics m;
  // The scans as traverse-carmen publishes them (configs/carmen.yaml defaults) and
  // traverse-frontend reads them: the same figures as scripts/eval-carmen.sh --stages frontend.
  const carmen::CarmenConfig carmen_config;
  // The reference by scan time: on a log subsampled by travel the frontend's result is the
  // previous scan's (matcher.sparse_lag), and finish() gives the last.
  std::map<int64_t, Pose2> reference;
  auto take = [&](const FrontendResult& r) {
    if (!r.has_pose()) return;
    if (r.status == ScanStatus::kPredicted) ++m.predicted;
    if (r.diagnostics && r.diagnostics->searched) ++m.searched;
    ref.push_back({r.utime, reference.at(r.utime)});
    est.push_back({r.utime, r.T_map_base, r.covariance});
    // CARMEN_TRACE=1: every step, reference against estimate, to find where tracking fails.
    if (std::getenv("CARMEN_TRACE") && ref.size() > 1) {
      const std::size_t i = ref.size() - 1;
      const Pose2 dr = between(ref[i - 1].pose, ref[i].pose);
      const Pose2 de = between(est[i - 1].pose, est[i].pose);
      std::printf("TRACE %zu ref %.3f %.3f %.1f est %.3f %.3f %.1f err %.3f res %.3f\n", i, dr.x(),
                  dr.y(), dr.theta() * 57.3, de.x(), de.y(), de.theta() * 57.3,
                  (dr.translation() - de.translation()).norm(),
                  r.diagnostics ? r.diagnostics->residual_rms : 0.0);
    }
  };
  while (auto s = reader.next()) {
    const Scan scan = to_planar_scan(carmen::to_scan_message(*s, carmen_config));
    reference[scan.utime_last] = Pose2(s->x_m, s->y_m, s->theta_rad);
    take(frontend->process(scan));
  }
  if (const auto r = frontend->finish()) take(*r);
  frontend->report([&m](const std::string& name, double value) {
    if (name == "scans_widened") m.widened = value;
    if (name == "scans_moved_by_widening") m.moved_by_widening = value;
  });
  m.scans = static_cast<int>(est.size());
  m.ev = evaluator::evaluate(est, ref, evaluator::EvaluatorConfig{});
  return m;
}

struct LogCase {
  const char* name;
  friend void PrintTo(const LogCase& c, std::ostream* os) { *os << c.name; }
  int min_scans;
  double max_rpe_1m_m, max_rpe_10m_m, max_jump_m;
  // Sparse logs only (their poses come from the wide search, whose covariance includes the score
  // surface's spread): at most this fraction of steps outside the 99 % ellipse, and a median NEES
  // between 0.1 (not inflated past 3.7 times a consistent sigma) and 1.39 (not optimistic in the
  // bulk). Negative: not checked.
  double max_outside_99_fraction = -1.0;
};

class CarmenLog : public ::testing::TestWithParam<LogCase> {};

TEST_P(CarmenLog, TracksReference) {
  const LogCase& c = GetParam();
  const std::string path = std::string("../shared/data/carmen/") + c.name + "-corrected.log.gz";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "no data at " << path;
  const Metrics m = run_log(path);
  const evaluator::Evaluation& ev = m.ev;
  ASSERT_EQ(ev.matched, static_cast<std::size_t>(m.scans));
  ASSERT_TRUE(ev.rpe_10m.rms_m && ev.step_consistency.nees_median);
  const double rpe_1m = *ev.rpe_1m.rms_m, rpe_10m = *ev.rpe_10m.rms_m;
  const double nees_median = *ev.step_consistency.nees_median;
  const double outside_99 = *ev.step_consistency.outside_99_fraction;
  std::printf(
      "%s: %d scans, %d predicted, %d searched, rpe_1m %.4f m, rpe_10m %.4f m, max_jump %.4f m, "
      "step NEES median %.2f, outside the 99 %% ellipse %.1f %%; widened %.0f, moved by it %.0f\n",
      c.name, m.scans, m.predicted, m.searched, rpe_1m, rpe_10m, ev.max_jump.step_error_m,
      nees_median, 100.0 * outside_99, m.widened, m.moved_by_widening);
  EXPECT_GT(m.scans, c.min_scans);
  EXPECT_EQ(m.predicted, 0);
  EXPECT_LT(rpe_1m, c.max_rpe_1m_m);
  EXPECT_LT(rpe_10m, c.max_rpe_10m_m);
  EXPECT_LT(ev.max_jump.step_error_m, c.max_jump_m);
  if (c.max_outside_99_fraction >= 0.0) {
    EXPECT_LT(outside_99, c.max_outside_99_fraction);
    EXPECT_GT(nees_median, 0.1);
    EXPECT_LT(nees_median, 1.39);
  }
}

// Bounds a little above what the frontend reaches (measured, configs/frontend.yaml with its
// five-member ensemble, its step prior for sparse scans and its lag of one scan on logs
// subsampled by travel; rpe_1m / rpe_10m / max_jump): freiburg-079 0.046 / 0.098 / 0.18 m, intel
// 0.059 / 0.119 / 0.45 m, aces 0.061 / 0.151 / 0.22 m, csail 0.056 / 0.144 / 0.41 m: issue 4's
// largest jump under 0.5 m on all four. Without the lag (matcher.sparse_lag false) intel jumped
// 0.87 m: scan 761, entering a room that an earlier pass mapped otherwise, matched 20 degrees off.
// Without the step prior (matcher.sparse_step_*), aces jumped 1.03 m (rpe_10m 0.47 m): steps
// along corridors stalled. These bounds guard the shipped start only; on a sparse log the outcome
// turns on where the grid's cells fall (scripts/frontend-sensitivity.sh). Before the gate on far
// searched poses (search_max_unverified_m), freiburg-079 jumped 0.75 m at a scan crowded by
// something near the scanner. Before the wide search for sparse scans, intel, aces and csail lost
// track (rpe_10m 2.97 / 4.31 / 4.18 m). Steps outside the 99 % ellipse of their covariance: intel
// 2.6 %, aces 0 %, csail 6.2 % (median NEES 0.37 / 0.23 / 0.71); with the Gauss-Newton covariance
// alone and one frontend (matcher.wide_search_temperature 0, sparse_ensemble_members 1): 70 / 60 /
// 60 %, median 18.8 / 13.3 / 14.5. freiburg-079 is a scanner's stream (Gauss-Newton covariance):
// 73.5 % outside, median 23.8, not checked.
INSTANTIATE_TEST_SUITE_P(Logs, CarmenLog,
                         ::testing::Values(LogCase{"freiburg-079", 4700, 0.06, 0.15, 0.5},
                                           LogCase{"intel", 900, 0.1, 0.2, 0.5, 0.1},
                                           LogCase{"aces", 430, 0.1, 0.25, 0.5, 0.05},
                                           LogCase{"csail", 400, 0.1, 0.25, 0.5, 0.2}),
                         [](const auto& info) {
                           std::string n = info.param.name;
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

}  // namespace
}  // namespace traverse::frontend
