#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "calibration/calibrated_frontend.hpp"
#include "calibration/extrinsic_yaw.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

// A wheeled cart's path: straight legs joined by arcs both ways and a weave of a few cm, its
// heading along the path (what the estimate relies on), sampled every `step_m`; a point `lever_m`
// ahead of the axle is what is tracked.
std::vector<Pose2> cart_path(double step_m, double lever_m) {
  std::vector<Pose2> path;
  Pose2 T;
  const auto drive = [&](double length_m, double curvature) {
    for (double s = 0.0; s < length_m; s += step_m) {
      // A slight weave on straight legs: the heading follows the path.
      const double k = curvature + (curvature == 0.0 ? 0.02 * std::sin(0.8 * s) : 0.0);
      T = T * Pose2::exp(Eigen::Vector3d(step_m, 0.0, k * step_m));
      path.push_back(T * Pose2(lever_m, 0.0, 0.0));
    }
  };
  for (int lap = 0; lap < 2; ++lap) {
    drive(12.0, 0.0);
    drive(2.0, 1.0 / 1.5);  // a left corner
    drive(10.0, 0.0);
    drive(3.0, -1.0 / 2.0);  // a right corner
    drive(15.0, 0.0);
  }
  return path;
}

// The poses a frontend tracking bhat (the base turned by delta) gives for a base path that starts
// at the map frame's origin: T_map_bhat = Rot(-delta) T_map_base Rot(delta).
std::vector<Pose2> as_tracked(const std::vector<Pose2>& path, double delta, double noise_m,
                              unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise_m);
  std::vector<Pose2> tracked;
  const Pose2 R(0.0, 0.0, delta);
  const Pose2 T0_inverse = path.front().inverse();
  for (const Pose2& T : path) {
    const Pose2 E = R.inverse() * (T0_inverse * T) * R;
    tracked.emplace_back(E.x() + n(rng), E.y() + n(rng), E.theta() + 0.1 * n(rng));
  }
  return tracked;
}

CalibrationConfig calibration() { return CalibrationConfig{}; }

// The yaw of a scanner turned by 0.3 or -0.1 deg on the cart comes back to 0.06 deg from 84 m of
// path with 2 mm of noise on every pose (a chord's angle 3 mrad), also when the tracked point lies
// 0.3 m ahead of the axle (its sideways slip on the weave must not bias the yaw; the corners
// turn too much within a chord to be taken).
TEST(ExtrinsicYaw, RecoversTheScannersYawFromTheCartsPath) {
  for (const double lever : {0.0, 0.3}) {
    for (const double delta : {0.00524, -0.00175}) {
      ExtrinsicYawEstimator estimator(calibration());
      const auto tracked = as_tracked(cart_path(0.01, lever), delta, 0.002, 7);
      for (std::size_t k = 0; k < tracked.size(); ++k) {
        estimator.add_pose(static_cast<int64_t>(k) * 20000, tracked[k]);
      }
      ASSERT_TRUE(estimator.yaw_rad().has_value());
      EXPECT_NEAR(*estimator.yaw_rad(), delta, 1e-3) << "lever " << lever;
      EXPECT_GT(estimator.travel_m(), 70.0);
    }
  }
}

// Until min_travel_m of chords went in, no estimate is given; turning on the spot adds none.
TEST(ExtrinsicYaw, NoEstimateBeforeEnoughTravel) {
  ExtrinsicYawEstimator estimator(calibration());
  Pose2 T;
  for (int k = 0; k < 200; ++k) {  // a turn on the spot
    T = T * Pose2(0.0, 0.0, 0.02);
    estimator.add_pose(k * 20000, T);
  }
  EXPECT_EQ(estimator.chords(), 0);
  const auto tracked = as_tracked(cart_path(0.01, 0.0), 0.003, 0.0, 1);
  for (std::size_t k = 0; k < 900; ++k)
    estimator.add_pose(static_cast<int64_t>(k) * 20000, tracked[k]);
  EXPECT_LT(estimator.travel_m(), 10.0);
  EXPECT_FALSE(estimator.yaw_rad().has_value());
}

// A yaw beyond max_yaw_rad is not applied (the rig file needs a calibration, not a correction).
TEST(ExtrinsicYaw, LargeYawIsNotApplied) {
  ExtrinsicYawEstimator estimator(calibration());
  const auto tracked = as_tracked(cart_path(0.01, 0.0), 0.1, 0.0, 1);
  for (std::size_t k = 0; k < tracked.size(); ++k) {
    estimator.add_pose(static_cast<int64_t>(k) * 20000, tracked[k]);
  }
  EXPECT_GT(estimator.travel_m(), 60.0);
  EXPECT_FALSE(estimator.yaw_rad().has_value());
}

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
