#include "frontend.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "config.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

using testing::kPeriodUs;
using testing::small_sweep;

// Walks, weaves and turns through the room; returns the final pose error [m] and [rad].
struct RoomRun {
  double position_error_m = 0.0, heading_error_rad = 0.0;
  std::map<std::string, double> counters;
  int last_voting = 0;  // ensemble members voting on the last step
};
RoomRun run_room(const FrontendConfig& config, bool with_imu, double turn_rate, int scans = 120) {
  const auto world = synthetic::room();
  // Starting from rest: speed and turn rate ramp up over 0.5 s (ramp is the integral of the
  // profile min(1, 2 s)), as a pushed cart does.
  auto ramp = [](double s) { return s < 0.5 ? s * s : s - 0.25; };
  auto truth = [&](int64_t t) {
    const double s = ramp(1e-6 * static_cast<double>(t));
    return Pose2(-2.0 + 0.5 * s, -1.0 + 0.3 * std::sin(s), turn_rate * s);
  };
  auto yaw_rate = [&](int64_t t) {
    return turn_rate * std::min(1.0, 2e-6 * static_cast<double>(t));
  };
  const auto frontend = make_frontend(config);
  std::mt19937 rng(3);
  RoomRun run;
  int64_t imu_t = 0;
  const Pose2 T_laser;
  Pose2 T_map_world;
  for (int k = 0; k < scans; ++k) {
    const Scan scan =
        synthetic::make_sweep(world, truth, T_laser, small_sweep(k * kPeriodUs), &rng);
    for (; with_imu && imu_t <= scan.utime_last; imu_t += 5000) {
      frontend->add_imu(imu_t, Eigen::Vector3d(0.01, -0.02, yaw_rate(imu_t)));
    }
    const FrontendResult r = frontend->process(scan);
    EXPECT_EQ(r.status, ScanStatus::kMatched);
    if (k == 0) {
      const auto& p = config.initial_pose;
      T_map_world = Pose2(p.x_m, p.y_m, p.theta_rad) * truth(scan.utime_last).inverse();
      EXPECT_NEAR((r.T_map_base.translation() - Eigen::Vector2d(p.x_m, p.y_m)).norm(), 0.0, 1e-12);
      EXPECT_NEAR(wrap_angle(r.T_map_base.theta() - p.theta_rad), 0.0, 1e-12);
    }
    const Pose2 T_map_base_true = T_map_world * truth(scan.utime_last);
    run.position_error_m = (r.T_map_base.translation() - T_map_base_true.translation()).norm();
    run.heading_error_rad = std::abs(wrap_angle(r.T_map_base.theta() - T_map_base_true.theta()));
    run.last_voting = r.diagnostics->ensemble_voting;
  }
  run.counters = testing::counters_of(*frontend);
  return run;
}

TEST(Frontend, TracksWalkThroughRoomWithImu) {
  const RoomRun run = run_room(FrontendConfig{}, true, 0.4);
  EXPECT_LT(run.position_error_m, 0.005);
  EXPECT_LT(run.heading_error_rad, 0.001);
  EXPECT_GT(run.counters.at("map_updates"), 2);
  EXPECT_GT(run.counters.at("imu_samples"), 500);
}

// Without IMU the sweep's rotation comes from the constant-velocity estimate.
TEST(Frontend, TracksWithoutImu) {
  const RoomRun run = run_room(FrontendConfig{}, false, 0.4);
  EXPECT_LT(run.position_error_m, 0.005);
  EXPECT_LT(run.heading_error_rad, 0.001);
  EXPECT_EQ(run.counters.at("imu_samples"), 0);
}

// Normal projection frees the axis along a surface for odometry to hold (matcher_for): a stream
// without odometry is matched on the whole gradient, to the bit, whatever the key says.
TEST(Frontend, NormalProjectionOnlyWhereOdometryPredicts) {
  FrontendConfig projected;
  projected.matcher.normal_projection = true;
  const RoomRun with = run_room(projected, true, 0.4);
  const RoomRun without = run_room(FrontendConfig{}, true, 0.4);
  EXPECT_EQ(with.position_error_m, without.position_error_m);
  EXPECT_EQ(with.heading_error_rad, without.heading_error_rad);
  EXPECT_LT(with.position_error_m, 0.005);
}

// The ICP frontend (icp/) through the same walk: the same messages, the same accuracy.
TEST(Frontend, IcpKindTracksWalkThroughRoomWithAndWithoutImu) {
  FrontendConfig config;
  config.kind = "icp";
  for (const bool imu : {true, false}) {
    const RoomRun run = run_room(config, imu, 0.4);
    EXPECT_LT(run.position_error_m, 0.005) << imu;
    EXPECT_LT(run.heading_error_rad, 0.001) << imu;
    EXPECT_GT(run.counters.at("map_updates"), 2);
    EXPECT_EQ(run.counters.at("scans_unverified"), 0);
  }
}

// A scanner's stream is matched by one frontend: the sparse-scan ensemble votes on its first
// scans only, then is dropped.
TEST(Frontend, ScannerStreamDropsTheSparseEnsemble) {
  FrontendConfig config;
  config.matcher.sparse_ensemble_members = 4;
  const RoomRun run = run_room(config, false, 0.4, 30);
  EXPECT_EQ(run.last_voting, 1);
  EXPECT_LT(run.position_error_m, 0.005);
  EXPECT_EQ(run.counters.at("steps_outvoted"), 0);
}

// The trajectory starts at the configured pose, off the grid's cells by a fraction of one and
// turned, and is tracked as well from there.
TEST(Frontend, TracksFromTheConfiguredInitialPose) {
  FrontendConfig config;
  config.initial_pose = {.x_m = 12.337, .y_m = -4.061, .theta_rad = 2.2};
  const RoomRun run = run_room(config, false, 0.4);
  EXPECT_LT(run.position_error_m, 0.005);
  EXPECT_LT(run.heading_error_rad, 0.001);
}

// Turning fast (1.5 rad/s, a turn on the spot's pace): de-skew removes the error that the sweep's
// own rotation puts into every scan and, through map updates, into the map.
TEST(Frontend, DeskewReducesErrorWhileTurningFast) {
  FrontendConfig on, off;
  off.deskew.enabled = false;
  const RoomRun with = run_room(on, true, 1.5);
  const RoomRun without = run_room(off, true, 1.5);
  EXPECT_LT(with.heading_error_rad, 0.002);
  EXPECT_LT(with.position_error_m, 0.005);
  EXPECT_GT(without.heading_error_rad, 0.01);
}

// A first scan too poor to match is flagged at the initial pose (there is nothing to predict
// from); the first good scan then starts the map there.
TEST(Frontend, BlindFirstScanIsPlacedAtTheInitialPose) {
  FrontendConfig config;
  config.initial_pose = {.x_m = 1.5, .y_m = -0.25, .theta_rad = 0.3};
  const auto frontend = make_frontend(config);
  std::mt19937 rng(9);
  const auto world = synthetic::room();
  const auto still = [](int64_t) { return Pose2(0.2, 0.1, 0.0); };
  Scan blind = synthetic::make_sweep(world, still, Pose2(), small_sweep(0), &rng);
  std::fill(blind.ranges.begin(), blind.ranges.end(), std::numeric_limits<float>::quiet_NaN());
  const Pose2 start(1.5, -0.25, 0.3);
  for (int k = 0; k < 3; ++k) {
    const FrontendResult r = k == 0 ? frontend->process(blind)
                                    : frontend->process(synthetic::make_sweep(
                                          world, still, Pose2(), small_sweep(k * kPeriodUs), &rng));
    ASSERT_EQ(r.status, k == 0 ? ScanStatus::kPredicted : ScanStatus::kMatched) << k;
    EXPECT_LT((r.T_map_base.translation() - start.translation()).norm(), 0.002) << k;
    EXPECT_LT(std::abs(wrap_angle(r.T_map_base.theta() - start.theta())), 0.001) << k;
  }
}

class FrontendBadScans : public ::testing::Test {
 protected:
  void SetUp() override {
    // Standing still for a few scans builds the map and the (zero) velocity.
    for (int k = 0; k < 5; ++k) {
      ASSERT_EQ(frontend_->process(good_scan(k)).status, ScanStatus::kMatched);
    }
  }
  Scan good_scan(int k) {
    return synthetic::make_sweep(
        world_, [](int64_t) { return Pose2(0.2, 0.1, 0.0); }, Pose2(), small_sweep(k * kPeriodUs),
        &rng_);
  }
  synthetic::World world_ = synthetic::room();
  std::mt19937 rng_{5};
  std::unique_ptr<Frontend> frontend_ = make_frontend(FrontendConfig{});
  double counter(const std::string& name) const {
    return testing::counters_of(*frontend_).at(name);
  }
};

TEST_F(FrontendBadScans, IgnoresNanZeroNegativeAndOutOfRangeReadings) {
  Scan scan = good_scan(5);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> bad = {nan, 0.0f, -1.0f, inf, 0.01f, 60.0f};
  int replaced = 0;
  for (std::size_t i = 0; i < scan.ranges.size(); i += 3) {
    scan.ranges[i] = bad[(i / 3) % bad.size()];
    ++replaced;
  }
  const double invalid_before = counter("readings_invalid");
  const FrontendResult r = frontend_->process(scan);
  EXPECT_EQ(r.status, ScanStatus::kMatched);
  EXPECT_EQ(r.diagnostics->valid_points, static_cast<int>(scan.ranges.size()) - replaced);
  EXPECT_EQ(counter("readings_invalid") - invalid_before, replaced);
  EXPECT_LT(r.T_map_base.translation().norm(), 0.005);  // still where it stood
}

TEST_F(FrontendBadScans, TooFewValidPointsGivesFlaggedPrediction) {
  Scan blind = good_scan(5);
  for (std::size_t i = 0; i < blind.ranges.size(); ++i) {
    if (i % 200 != 0) blind.ranges[i] = std::numeric_limits<float>::quiet_NaN();
  }
  const FrontendResult r = frontend_->process(blind);
  EXPECT_EQ(r.status, ScanStatus::kPredicted);
  EXPECT_EQ(r.diagnostics->valid_points, 9);
  EXPECT_LT(r.T_map_base.translation().norm(), 0.005);  // constant (zero) velocity
  EXPECT_GT(r.covariance(0, 0), 0.1);                   // and honest about it
  EXPECT_EQ(counter("scans_predicted"), 1);
  // An empty scan is too few points as well; the next good scan is matched again.
  Scan empty = good_scan(6);
  empty.ranges.clear();
  EXPECT_EQ(frontend_->process(empty).status, ScanStatus::kPredicted);
  EXPECT_EQ(frontend_->process(good_scan(7)).status, ScanStatus::kMatched);
  EXPECT_EQ(counter("scans_predicted"), 2);
}

TEST_F(FrontendBadScans, DropsScansWhoseTimeGoesBackOrIsInconsistent) {
  Scan reversed = good_scan(5);
  std::swap(reversed.utime_first, reversed.utime_last);  // last point before the first
  EXPECT_EQ(frontend_->process(reversed).status, ScanStatus::kDropped);
  EXPECT_EQ(frontend_->process(good_scan(2)).status, ScanStatus::kDropped);  // back in time
  EXPECT_EQ(frontend_->process(good_scan(4)).status, ScanStatus::kDropped);  // same time again
  EXPECT_EQ(counter("scans_dropped_time"), 3);
  EXPECT_EQ(frontend_->process(good_scan(5)).status, ScanStatus::kMatched);
}

TEST(Frontend, ShippedConfigLoadsAndIsUsable) {
  FrontendConfig config;
  load_config("configs/frontend.yaml", config);
  EXPECT_EQ(validate(config), std::nullopt);
  FrontendConfig negative_temperature = config;
  negative_temperature.matcher.wide_search_temperature = -1.0;
  const auto problem = validate(negative_temperature);
  ASSERT_NE(problem, std::nullopt);
  EXPECT_NE(problem->find("matcher.wide_search_temperature"), std::string::npos) << *problem;
  FrontendConfig nan_start = config;
  nan_start.initial_pose.theta_rad = std::numeric_limits<double>::quiet_NaN();
  const auto start_problem = validate(nan_start);
  ASSERT_NE(start_problem, std::nullopt);
  EXPECT_NE(start_problem->find("initial_pose"), std::string::npos) << *start_problem;
  FrontendConfig no_lag_window = config;
  no_lag_window.matcher.sparse_lag_window_m = 0.0;
  const auto lag_problem = validate(no_lag_window);
  ASSERT_NE(lag_problem, std::nullopt);
  EXPECT_NE(lag_problem->find("matcher.sparse_lag_window_m"), std::string::npos) << *lag_problem;
  FrontendConfig unbounded_hold = config;
  unbounded_hold.matcher.degeneracy_hold_without_odometry = true;
  unbounded_hold.motion_prior.max_acceleration_mps2 = 0.0;
  const auto hold_problem = validate(unbounded_hold);
  ASSERT_NE(hold_problem, std::nullopt);
  EXPECT_NE(hold_problem->find("matcher.degeneracy_hold_without_odometry"), std::string::npos)
      << *hold_problem;
  config.map.levels = 0;
  EXPECT_NE(validate(config), std::nullopt);
}

TEST(Frontend, DropsImuSamplesGoingBack) {
  const auto frontend = make_frontend(FrontendConfig{});
  EXPECT_TRUE(frontend->add_imu(100, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(frontend->add_imu(50, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(frontend->add_imu(200, Eigen::Vector3d(0, 0, std::nan(""))));
  const auto counters = testing::counters_of(*frontend);
  EXPECT_EQ(counters.at("imu_samples"), 1);
  EXPECT_EQ(counters.at("imu_dropped"), 2);
}

// Stands still in the room for five scans, then people crowd round the scanner: most of the
// sixth sweep ends on them, not on the mapped room. Returns that scan's result.
struct CrowdedRun {
  FrontendResult result;
  std::map<std::string, double> counters;
};
CrowdedRun run_crowded(const FrontendConfig& config) {
  const auto frontend = make_frontend(config);
  const Pose2 T(0.2, 0.1, 0.0);
  auto still = [&](int64_t) { return T; };
  std::mt19937 rng(5);
  for (int k = 0; k < 5; ++k) {
    const Scan scan =
        synthetic::make_sweep(synthetic::room(), still, Pose2(), small_sweep(k * kPeriodUs), &rng);
    EXPECT_EQ(frontend->process(scan).status, ScanStatus::kMatched);
  }
  synthetic::World crowded = synthetic::room();
  for (int i = 0; i < 14; ++i) {  // a person: 0.4 m x 0.3 m, 0.8 to 1.1 m away
    const double a = 2.0 * M_PI * i / 14, d = 0.8 + 0.1 * (i % 4);
    const double cx = T.x() + d * std::cos(a), cy = T.y() + d * std::sin(a);
    crowded.push_back({{cx - 0.2, cy - 0.15}, {cx + 0.2, cy - 0.15}});
    crowded.push_back({{cx + 0.2, cy - 0.15}, {cx + 0.2, cy + 0.15}});
    crowded.push_back({{cx + 0.2, cy + 0.15}, {cx - 0.2, cy + 0.15}});
    crowded.push_back({{cx - 0.2, cy + 0.15}, {cx - 0.2, cy - 0.15}});
  }
  CrowdedRun run;
  run.result = frontend->process(
      synthetic::make_sweep(crowded, still, Pose2(), small_sweep(5 * kPeriodUs), &rng));
  run.counters = testing::counters_of(*frontend);
  return run;
}

TEST(Frontend, ScanThatFitsNowhereGetsTheFlaggedPredictionAndStaysOutOfTheMap) {
  FrontendConfig config;
  load_config("configs/frontend.yaml", config);
  const CrowdedRun run = run_crowded(config);
  const FrontendResult& r = run.result;
  EXPECT_EQ(r.status, ScanStatus::kPredicted);
  EXPECT_GT(r.diagnostics->residual_rms, config.matcher.search_trigger_residual);
  EXPECT_LT(r.T_map_base.translation().norm(), 0.005);  // where it stood (the map frame's origin)
  EXPECT_LT(std::abs(r.T_map_base.theta()), 0.002);
  EXPECT_GT(r.covariance(0, 0), 0.2);  // the prior's 0.5 m, squared, on top of the last
  EXPECT_FALSE(r.diagnostics->map_updated);
  EXPECT_EQ(run.counters.at("scans_unverified"), 1);
  EXPECT_EQ(run.counters.at("scans_predicted"), 0);
  // Without the rule the same scan moves the pose by metres (measured: 1.54 m and 0.18 rad,
  // Gauss-Newton drawn off by the people), so the case above tests something.
  config.matcher.search_max_unverified_m = 1e9;
  config.matcher.search_max_unverified_rad = 1e9;
  const CrowdedRun off = run_crowded(config);
  EXPECT_EQ(off.result.status, ScanStatus::kMatched);
  EXPECT_GT(off.result.T_map_base.translation().norm(), 0.3);
}

}  // namespace
}  // namespace traverse::frontend
