// Handing over between frontends while the node runs (handover.hpp, frontend_node.hpp): a
// FRONTEND_CONTROL request swaps Hector for ICP mid-walk without a jump, and a session saved by
// one node is resumed by the next, which checks its first scans against the saved ones.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "frontend_node.hpp"
#include "scan_message.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::frontend {
namespace {

using testing::kPeriodUs;
using testing::small_sweep;

// The walk of frontend_test.cpp's room, as messages: scan k and the IMU samples before it.
Pose2 truth(int64_t t) {
  const double s = 1e-6 * static_cast<double>(t);
  const double r = s < 0.5 ? s * s : s - 0.25;
  return Pose2(-2.0 + 0.5 * r, -1.0 + 0.3 * std::sin(r), 0.4 * r);
}

class HandoverTest : public ::testing::Test {
 protected:
  // A node on a bus of its own (a node cannot leave a bus: each run gets a new one).
  std::unique_ptr<FrontendNode> make_node(const std::string& state_dir = "") {
    buses_.push_back(std::make_unique<Bus>("memq://"));
    buses_.back()->subscribe<pose2d_t>(config_.pose_channel,
                                       [this](const pose2d_t& p) { poses_.push_back(p); });
    return std::make_unique<FrontendNode>(
        bus(), config_, [this](const std::string& k, double v) { counters_[k] = v; }, state_dir);
  }
  Bus& bus() { return *buses_.back(); }
  void handle_all() {
    while (bus().lcm().handleTimeout(0) > 0) {
    }
  }
  // Publishes scans [from, to) of the walk in `world`, moved by T_shift, with IMU samples.
  void drive(int from, int to, const synthetic::World& world = synthetic::room(),
             const Pose2& T_shift = Pose2()) {
    std::mt19937 rng(3 + from);
    const auto moved = [&](int64_t t) { return T_shift * truth(t); };
    for (int k = from; k < to; ++k) {
      const Scan scan =
          synthetic::make_sweep(world, moved, Pose2(), small_sweep(k * kPeriodUs), &rng);
      for (; imu_t_ <= scan.utime_last; imu_t_ += 5000) {
        imu_t imu{};
        imu.utime = imu_t_;
        imu.frame = "imu";
        imu.angular_velocity[2] = 0.4 * std::min(1.0, 2e-6 * static_cast<double>(imu_t_));
        bus().publish(config_.imu_channel, imu);
      }
      auto msg = to_planar_scan_message(scan, "laser_horizontal", k);
      bus().publish(config_.scan_channel, msg);
      handle_all();
    }
  }
  void request(int64_t id, const std::string& kind) {
    frontend_control_t m{};
    m.utime = imu_t_;
    m.request_id = id;
    m.kind = kind;
    bus().publish(config_.handover.control_channel, m);
    handle_all();
  }
  // Position error of every published pose against the truth, in the map frame of the first.
  std::vector<double> errors() const {
    const Pose2 T_map_world = truth(poses_.front().utime).inverse();
    std::vector<double> e;
    for (const pose2d_t& p : poses_) {
      e.push_back(
          ((T_map_world * truth(p.utime)).translation() - Eigen::Vector2d(p.x, p.y)).norm());
    }
    return e;
  }

  std::vector<std::unique_ptr<Bus>> buses_;
  FrontendConfig config_;
  std::vector<pose2d_t> poses_;
  std::map<std::string, double> counters_;
  int64_t imu_t_ = 0;
};

TEST_F(HandoverTest, SwapMidWalkContinuesWithoutAJump) {
  auto node = make_node();
  drive(0, 60);
  request(1, "icp");
  request(1, "icp");       // a repeat of the same request: carried out once
  request(2, "gmapping");  // not a kind: refused, counted
  drive(60, 120);
  node->flush(true);  // as the program at the end: the last scan waits for no more IMU
  handle_all();
  node->report_counters();
  EXPECT_EQ(counters_.at("frontend_swaps"), 1);
  EXPECT_EQ(counters_.at("frontend_kind_icp"), 1);
  EXPECT_EQ(counters_.at("frontend_request_id"), 2);
  EXPECT_EQ(counters_.at("frontend_control_rejected"), 1);
  EXPECT_GT(counters_.at("icp_iterations"), 0);  // the ICP frontend's own counter
  EXPECT_LT(counters_.at("handover_misfit_m"), 0.005);
  ASSERT_EQ(poses_.size(), 120u);
  const auto e = errors();
  for (std::size_t k = 1; k < e.size(); ++k) {
    EXPECT_LT(std::abs(e[k] - e[k - 1]), 0.002) << "scan " << k;
  }
  EXPECT_LT(e.back(), 0.005);
}

TEST_F(HandoverTest, SavedSessionResumesInTheSameMapAndRefusesAnotherPlace) {
  const auto dir = std::filesystem::temp_directory_path() / "traverse-handover-test";
  std::filesystem::remove_all(dir);
  {
    auto first = make_node(dir.string());
    drive(0, 60);
    first->flush(true);
    handle_all();
    first->save_state();
  }
  ASSERT_TRUE(std::filesystem::exists(dir / "frontend.state"));
  const std::size_t first_session = poses_.size();
  {
    auto resumed = make_node(dir.string());
    ASSERT_TRUE(resumed->resumed_scans());
    EXPECT_GT(*resumed->resumed_scans(), 10);
    drive(60, 120);
    resumed->flush(true);
    handle_all();
    EXPECT_TRUE(resumed->resume_failure().empty()) << resumed->resume_failure();
  }
  ASSERT_EQ(poses_.size(), 120u);
  const auto e = errors();
  EXPECT_LT(std::abs(e[first_session] - e[first_session - 1]), 0.002);
  EXPECT_LT(e.back(), 0.005);
  // Started again somewhere else (the walk moved 3 m into a corridor): the first scan does not
  // fit the saved map at the saved pose, the node says so and publishes nothing.
  poses_.clear();
  {
    auto elsewhere = make_node(dir.string());
    drive(120, 130, synthetic::corridor(30.0, 2.0), Pose2(3.0, 0.0, 0.0));
    EXPECT_NE(elsewhere->resume_failure().find("does not fit the saved map"), std::string::npos)
        << elsewhere->resume_failure();
  }
  EXPECT_TRUE(poses_.empty());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::frontend
