// The lag of one scan (sparse/lag.hpp) around a scripted two-phase frontend, and the Hector
// frontend's tentative integration that the lag relies on.
#include "sparse/lag.hpp"

#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "hector/hector_frontend.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

// A two-phase frontend whose scans are measured where a script says (by the scan's time), whose
// evidence is a function of the pose, and which keeps a ledger of the poses integrated: what a
// motion model derives its state from.
class ScriptedFrontend final : public TwoPhaseFrontend {
 public:
  std::map<int64_t, Pose2> measured;  // by the scan's last time
  std::vector<Pose2> truth;           // evidence 1 at truth[k] of scan k, falling off with distance
  std::vector<std::pair<int64_t, Pose2>> ledger;  // (utime, pose) integrated, in order

  bool add_imu(int64_t, const Eigen::Vector3d&) override { return true; }
  bool add_odometry(const OdometrySample&) override { return true; }
  Measurement measure(const Scan& scan) override {
    Measurement m;
    m.result.status = ScanStatus::kMatched;
    m.result.utime = scan.utime_last;
    m.result.T_map_base = measured.at(scan.utime_last);
    m.result.sparse = true;
    m.subsampled_by_travel = ledger.size() >= 4;
    m.points_matched.resize(100);
    return m;
  }
  void integrate(Measurement& m) override {
    ledger.emplace_back(m.result.utime, m.result.T_map_base);
  }
  // The best pose in the window is its centre.
  Measurement rematch(const Measurement& m, const SearchArea& area) const override {
    Measurement out = m;
    out.result.T_map_base = area.T_centre;
    return out;
  }
  double evidence(const Measurement& m, const Pose2& T) const override {
    const Pose2& t = truth.at(static_cast<std::size_t>(m.result.utime / 1'000'000));
    return 1.0 - (T.translation() - t.translation()).norm() - std::abs(T.theta() - t.theta());
  }
  Pose2 last_pose() const override { return ledger.empty() ? Pose2() : ledger.back().second; }
  void begin_tentative() override { saved_ = ledger; }
  void rollback() override { ledger = saved_; }
  void commit() override {}
  std::size_t map_bytes() const override { return 0; }
  void report(const CounterSink&) const override {}

 private:
  std::vector<std::pair<int64_t, Pose2>> saved_;
};

Scan scan_at(int k) {
  Scan s;
  s.utime_first = s.utime_last = 1'000'000LL * k;
  return s;
}

// Scans 1 m apart along x; scan 5 is measured 0.5 m to the side and turned 0.4 rad, where the
// map (the evidence) says it is not. The lag moves it to the pose halfway between scans 4 and 6,
// and what is integrated from then on (the ledger a motion model is derived from) holds scan 5
// where it settled, never where it was first measured, with scan 6 matched again after it.
TEST(SparseLag, MovesAScanTheNextOneContradictsAndIntegratesOnlyWhereItSettled) {
  auto scripted = std::make_unique<ScriptedFrontend>();
  ScriptedFrontend& f = *scripted;
  for (int k = 0; k < 9; ++k) {
    f.truth.emplace_back(k, 0.0, 0.0);
    f.measured[1'000'000LL * k] = k == 5 ? Pose2(5.0, 0.5, 0.4) : Pose2(k, 0.0, 0.0);
  }
  SparseLag lag(std::move(scripted), MatcherConfig{});
  std::vector<FrontendResult> results;
  for (int k = 0; k < 9; ++k) results.push_back(lag.process(scan_at(k)));
  const std::optional<FrontendResult> last = lag.finish();
  ASSERT_TRUE(last);
  results.push_back(*last);

  // Scans 0 to 3 come at once (the stream is not yet known to be subsampled), scan 4 is the first
  // held, and from then on each result is the scan before's.
  EXPECT_EQ(results[4].status, ScanStatus::kHeld);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(results[k].utime, 1'000'000LL * k) << k;
  for (int k = 5; k < 10; ++k) EXPECT_EQ(results[k].utime, 1'000'000LL * (k - 1)) << k;
  const FrontendResult& moved = results[6];
  EXPECT_NEAR((moved.T_map_base.translation() - Eigen::Vector2d(5.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(moved.T_map_base.theta(), 0.0, 1e-12);
  std::map<std::string, double> counters;
  lag.report([&](const std::string& k, double v) { counters[k] = v; });
  EXPECT_EQ(counters.at("scans_revised"), 1);

  ASSERT_EQ(f.ledger.size(), 9u);
  for (int k = 0; k < 9; ++k) {
    EXPECT_EQ(f.ledger[k].first, 1'000'000LL * k) << k;
    EXPECT_NEAR((f.ledger[k].second.translation() - Eigen::Vector2d(k, 0.0)).norm(), 0.0, 1e-12)
        << k;
  }
}

// A tentative integration undone leaves the Hector frontend as if it had never seen the scan: the
// map and the motion model (last pose, velocity, the stream's intervals) alike.
TEST(HectorFrontend, RollbackUndoesAnIntegrationExactly) {
  FrontendConfig config;
  const auto world = synthetic::room();
  synthetic::SweepSpec spec;
  spec.n_ranges = 900;
  spec.angle_step = 300.0 * M_PI / 180.0 / 899.0;
  const auto sweep = [&](int k) {
    spec.utime_first = 100'000LL * k;
    return synthetic::make_sweep(
        world, [](int64_t t) { return Pose2(-1.0 + 0.5e-6 * t, 0.2, 0.3e-6 * t); }, Pose2(), spec);
  };
  HectorFrontend a(config), b(config);
  for (int k = 0; k < 5; ++k) {
    for (HectorFrontend* f : {&a, &b}) {
      Measurement m = f->measure(sweep(k));
      f->integrate(m);
    }
  }
  // a sees scan 5 tentatively, far off, then takes it back; b never sees it.
  Measurement odd = a.measure(sweep(5));
  odd.result.T_map_base = Pose2(2.0, -1.0, 1.0);
  a.begin_tentative();
  a.integrate(odd);
  ASSERT_NE(a.last_pose().vector(), b.last_pose().vector());
  a.rollback();
  EXPECT_EQ(a.last_pose().vector(), b.last_pose().vector());
  EXPECT_EQ(a.map_bytes(), b.map_bytes());
  for (int k = 6; k < 9; ++k) {
    Measurement ma = a.measure(sweep(k)), mb = b.measure(sweep(k));
    EXPECT_EQ(ma.result.T_map_base.vector(), mb.result.T_map_base.vector()) << k;
    EXPECT_EQ(ma.result.covariance, mb.result.covariance) << k;
    a.integrate(ma);
    b.integrate(mb);
  }
}

}  // namespace
}  // namespace traverse::frontend
