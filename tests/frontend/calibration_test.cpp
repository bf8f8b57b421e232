#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "calibration/calibrated_frontend.hpp"
#include "cart_path.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

using traverse::test::as_tracked;
using traverse::test::cart_path;

// A frontend that publishes given poses (matched, covariance diag(4, 1, 1e-4)) and records the
// odometry it receives.
class ScriptedFrontend final : public Frontend {
 public:
  explicit ScriptedFrontend(std::vector<Pose2> poses) : poses_(std::move(poses)) {}
  bool add_imu(int64_t, const Eigen::Vector3d&) override { return true; }
  bool add_odometry(const OdometrySample& o) override {
    odometry.push_back(o);
    return true;
  }
  FrontendResult process(const Scan& scan) override {
    FrontendResult r;
    r.status = ScanStatus::kMatched;
    r.utime = scan.utime_last;
    r.T_map_base = poses_.at(next_++);
    r.covariance = Eigen::Vector3d(4.0, 1.0, 1e-4).asDiagonal();
    return r;
  }
  std::optional<FrontendResult> finish() override { return std::nullopt; }
  std::size_t map_bytes() const override { return 0; }
  void report(const CounterSink&) const override {}
  std::vector<OdometrySample> odometry;

 private:
  std::vector<Pose2> poses_;
  std::size_t next_ = 0;
};

// The wrapper turns the tracked frame's poses back into the base's: positions about the initial
// pose by the estimated yaw, headings kept, covariances turned alike; odometry goes in turned
// into the tracked frame. Before the estimate holds, poses pass unchanged.
TEST(CalibratedFrontend, PublishesTheBasePathOnceTheYawIsKnown) {
  const double delta = 0.004;
  FrontendConfig config;
  config.initial_pose = {.x_m = 3.0, .y_m = -2.0, .theta_rad = 0.7};
  const Pose2 T0 = config.initial_pose.pose();
  const auto path = cart_path(0.02, 0.0);
  std::vector<Pose2> tracked;
  for (const Pose2& E : as_tracked(path, delta, 0.0, 1)) tracked.push_back(T0 * E);
  auto scripted = std::make_unique<ScriptedFrontend>(tracked);
  ScriptedFrontend& inner = *scripted;
  CalibratedFrontend frontend(std::move(scripted), config);
  const Pose2 T_start = path.front().inverse();
  for (std::size_t k = 0; k < tracked.size(); ++k) {
    Scan scan;
    scan.utime_first = static_cast<int64_t>(k) * 40000;
    scan.utime_last = scan.utime_first + 20000;
    const FrontendResult r = frontend.process(scan);
    const Pose2 truth = T0 * (T_start * path[k]);
    if (k < 100) {  // 2 m: no estimate yet
      EXPECT_NEAR((r.T_map_base.translation() - tracked[k].translation()).norm(), 0.0, 1e-12);
    }
    if (k + 1 == tracked.size()) {
      EXPECT_LT((r.T_map_base.translation() - truth.translation()).norm(), 0.003);
      EXPECT_NEAR(wrap_angle(r.T_map_base.theta() - truth.theta()), 0.0, 1e-9);
      // diag(4, 1) turned by the yaw: off-diagonal (4 - 1) cos sin.
      EXPECT_NEAR(r.covariance(0, 1), 3.0 * std::sin(delta) * std::cos(delta), 2e-4);
      EXPECT_GT((tracked[k].translation() - truth.translation()).norm(), 0.1);
    }
  }
  OdometrySample o;
  o.utime = 1;
  o.T_odom_base = Pose2(1.0, 2.0, 0.5);
  frontend.add_odometry(o);
  ASSERT_EQ(inner.odometry.size(), 1u);
  EXPECT_NEAR(inner.odometry[0].T_odom_base.theta(), 0.5 + delta, 3e-4);
  EXPECT_NEAR(inner.odometry[0].T_odom_base.x(), 1.0, 1e-12);
  const auto counters = testing::counters_of(frontend);
  EXPECT_NEAR(counters.at("extrinsic_yaw_rad"), delta, 3e-4);
}

}  // namespace
}  // namespace traverse::frontend
