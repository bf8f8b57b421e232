#include "frontend_node.hpp"

#include <gtest/gtest.h>

#include <map>

#include "scan_message.hpp"
#include "synthetic_scans.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::frontend {
namespace {

imu_t imu_at(int64_t utime) {
  imu_t m{};
  m.utime = utime;
  m.frame = "imu";
  return m;
}

class FrontendNodeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    config_.scan_channel = "TEST_SCAN";
    config_.pose_channel = "TEST_POSE";
    node_ = std::make_unique<FrontendNode>(
        bus_, config_, [this](const std::string& k, double v) { counters_[k] = v; });
    bus_.subscribe<pose2d_t>("TEST_POSE", [this](const pose2d_t& p) { poses_.push_back(p); });
  }
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }
  planar_scan_t scan(int k) {
    synthetic::SweepSpec spec;
    spec.n_ranges = 900;
    spec.angle_step = 300.0 * M_PI / 180.0 / 899.0;
    spec.utime_first = 1'000'000 + k * 20964;
    return to_planar_scan_message(
        synthetic::make_sweep(
            synthetic::room(), [](int64_t) { return Pose2(); }, Pose2(), spec),
        "laser_horizontal");
  }

  Bus bus_{"memq://"};
  FrontendConfig config_;
  std::unique_ptr<FrontendNode> node_;
  std::vector<pose2d_t> poses_;
  std::map<std::string, double> counters_;
};

TEST_F(FrontendNodeTest, PublishesOnePosePerScanWithoutImu) {
  for (int k = 0; k < 3; ++k) {
    auto m = scan(k);
    bus_.publish("TEST_SCAN", m);
  }
  handle_all();
  ASSERT_EQ(poses_.size(), 3u);
  for (const auto& p : poses_) {
    EXPECT_EQ(p.parent_frame, "map");
    EXPECT_EQ(p.child_frame, "base");
    EXPECT_EQ(p.flags, 0);
    EXPECT_NEAR(p.x, 0.0, 0.005);
    EXPECT_DOUBLE_EQ(p.covariance[1], p.covariance[3]);  // symmetric
    EXPECT_GT(p.covariance[0], 0.0);
  }
  EXPECT_EQ(poses_[2].utime, scan(2).utime_last);
  node_->report_counters();
  EXPECT_EQ(counters_.at("scans_matched"), 3);
  EXPECT_GT(counters_.at("map_bytes"), 0);
}

TEST_F(FrontendNodeTest, LogSubsampledByTravelIsPublishedOneScanLateAndTheLastAtShutdown) {
  FrontendConfig config = config_;
  config.pose_channel = "TEST_POSE_SPARSE";
  config.matcher.sparse_ensemble_members = 1;
  ASSERT_TRUE(config.matcher.sparse_lag);
  FrontendNode node(bus_, config);
  std::vector<pose2d_t> poses;
  bus_.subscribe<pose2d_t>("TEST_POSE_SPARSE", [&](const pose2d_t& p) { poses.push_back(p); });
  // Scans 1 s apart, walking 0.3 m per scan along x.
  std::vector<int64_t> utimes;
  for (int k = 0; k < 9; ++k) {
    synthetic::SweepSpec spec;
    spec.n_ranges = 900;
    spec.angle_step = 300.0 * M_PI / 180.0 / 899.0;
    spec.utime_first = 1'000'000 + k * 1'000'000LL;
    const Pose2 T(-1.5 + 0.3 * k, 0.0, 0.0);
    auto m =
        to_planar_scan_message(synthetic::make_sweep(
                                   synthetic::room(), [&](int64_t) { return T; }, Pose2(), spec),
                               "laser_horizontal");
    utimes.push_back(m.utime_last);
    bus_.publish("TEST_SCAN", m);
  }
  handle_all();
  // Six scans show the stream's pace; from the seventh on the pose comes with the next scan.
  ASSERT_EQ(poses.size(), 8u);
  node.flush(true);
  handle_all();
  ASSERT_EQ(poses.size(), 9u);
  for (int k = 0; k < 9; ++k) {
    EXPECT_EQ(poses[k].utime, utimes[k]) << k;
    EXPECT_NEAR(poses[k].x - poses[0].x, 0.3 * k, 0.05) << k;
  }
}

TEST_F(FrontendNodeTest, ScanWaitsForImuCoveringItsLastPoint) {
  auto i0 = imu_at(900'000);
  bus_.publish(config_.imu_channel, i0);
  auto s0 = scan(0);
  bus_.publish("TEST_SCAN", s0);
  handle_all();
  EXPECT_TRUE(poses_.empty());  // IMU has not reached the sweep's end yet
  auto i1 = imu_at(s0.utime_last + 1000);
  bus_.publish(config_.imu_channel, i1);
  handle_all();
  EXPECT_EQ(poses_.size(), 1u);
}

TEST_F(FrontendNodeTest, TooFewPointsIsPublishedFlaggedAndCounted) {
  auto s0 = scan(0);
  bus_.publish("TEST_SCAN", s0);
  auto s1 = scan(1);
  for (auto& r : s1.ranges) r = 0.0f;
  bus_.publish("TEST_SCAN", s1);
  handle_all();
  ASSERT_EQ(poses_.size(), 2u);
  EXPECT_EQ(poses_[1].flags & pose2d_t::FLAG_PREDICTED, pose2d_t::FLAG_PREDICTED);
  node_->report_counters();
  EXPECT_EQ(counters_.at("scans_predicted"), 1);
  EXPECT_EQ(counters_.at("readings_invalid"), 900);
}

}  // namespace
}  // namespace traverse::frontend
