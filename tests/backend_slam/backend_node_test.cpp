#include "backend_node.hpp"

#include <gtest/gtest.h>

#include <map>

#include "drive_feed.hpp"
#include "traverse/key_poses_t.hpp"

namespace traverse::backend {
namespace {

class BackendNodeTest : public ::testing::Test {
 protected:
  // Feeds a drive through the node over memq:// and collects its output.
  void run(const BackendNodeConfig& config, double duration_s) {
    ASSERT_EQ(validate(config), std::nullopt);
    BackendNode node(bus_, config, [this](const std::string& k, double v) { counters_[k] = v; });
    bus_.subscribe<key_poses_t>(channels::kKeyPoses,
                                [this](const key_poses_t& m) { messages_.push_back(m); });
    bus_.subscribe<pose2d_t>(channels::kPoseBackend,
                             [this](const pose2d_t& m) { trajectory_.push_back(m); });
    const test::Drive d = test::drive_ellipse(duration_s);
    for (std::size_t k = 0; k < d.utimes.size(); ++k) {
      test::publish_drive_step(bus_, d, k);
      handle_all();
    }
    node.finish();
    handle_all();
    node.report_counters();
    key_poses_ = static_cast<int>(node.backend().key_poses().size());
  }
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }

  Bus bus_{"memq://"};
  std::map<std::string, double> counters_;
  std::vector<key_poses_t> messages_;
  std::vector<pose2d_t> trajectory_;
  int key_poses_ = 0;
};

TEST_F(BackendNodeTest, MessagesStayIncrementalAsTheGraphGrows) {
  BackendNodeConfig config;
  config.backend.loop.min_travel_m = 1e6;  // no loop closure: a growing chain
  run(config, 12.0);
  ASSERT_GE(key_poses_, 30);
  ASSERT_EQ(static_cast<int>(messages_.size()), key_poses_);  // one optimisation per key pose
  for (const key_poses_t& m : messages_) {
    // Only the new key pose: in a chain the older marginals do not change.
    EXPECT_LE(m.n_poses, 1) << "optimisation " << m.optimisation;
    EXPECT_EQ(m.part, 0);
    EXPECT_EQ(m.parts, 1);
  }
  EXPECT_EQ(messages_.back().total_key_poses, key_poses_);
  EXPECT_EQ(messages_.back().optimisation, key_poses_);
  EXPECT_LT(messages_.back().getEncodedSize(), 1000);  // [bytes]
  // Each key pose once on the trajectory channel, flagged, in time order.
  ASSERT_EQ(static_cast<int>(trajectory_.size()), key_poses_);
  for (std::size_t i = 1; i < trajectory_.size(); ++i) {
    EXPECT_GT(trajectory_[i].utime, trajectory_[i - 1].utime);
    EXPECT_EQ(trajectory_[i].flags, pose2d_t::FLAG_KEY_POSE);
  }
  EXPECT_EQ(counters_.at("key_poses"), key_poses_);
  EXPECT_EQ(counters_.at("loop_closures"), 0.0);
}

TEST_F(BackendNodeTest, LoopClosuresRepublishMovedPosesInBoundedParts) {
  BackendNodeConfig config;
  config.max_poses_per_message = 10;
  config.backend.frontend_sigma_xy_m = 0.015;  // this drifting frontend's real precision per link
  config.backend.frontend_sigma_theta_rad = 0.005;
  run(config, 18.0);
  ASSERT_GT(counters_.at("loop_closures"), 0.0);
  int closures = 0, multipart = 0;
  for (const key_poses_t& m : messages_) {
    EXPECT_LE(m.n_poses, 10);
    closures += m.n_closures;
    if (m.parts > 1) ++multipart;
    for (const loop_closure_t& c : m.closures) {
      EXPECT_LT(c.from_id, c.to_id);
      EXPECT_LT(c.from_utime, c.utime);
    }
  }
  EXPECT_EQ(closures, counters_.at("loop_closures"));
  EXPECT_GT(multipart, 0);  // a closure moved more than 10 key poses
  EXPECT_GT(counters_.at("optimisation_total_s"), 0.0);
}

}  // namespace
}  // namespace traverse::backend
