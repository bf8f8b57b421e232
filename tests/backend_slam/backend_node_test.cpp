#include "backend_node.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "drive_feed.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose_graph_edges_t.hpp"

namespace traverse::backend {
namespace {

class BackendNodeTest : public ::testing::Test {
 protected:
  // Feeds a drive through the node over memq:// and collects its output.
  // late_every > 0: every late_every-th pose is flagged FLAG_LATE (publish_drive_step).
  void run(const BackendNodeConfig& config, double duration_s, std::size_t late_every = 0) {
    ASSERT_EQ(validate(config), std::nullopt);
    BackendNode node(bus_, config, [this](const std::string& k, double v) { counters_[k] = v; });
    bus_.subscribe<key_poses_t>(channels::kKeyPoses,
                                [this](const key_poses_t& m) { messages_.push_back(m); });
    bus_.subscribe<pose2d_t>(channels::kPoseBackend,
                             [this](const pose2d_t& m) { trajectory_.push_back(m); });
    bus_.subscribe<pose_graph_edges_t>(
        channels::kPoseGraphEdges, [this](const pose_graph_edges_t& m) { edges_.push_back(m); });
    const test::Drive d = test::drive_ellipse(duration_s);
    for (std::size_t k = 0; k < d.utimes.size(); ++k) {
      const bool late = late_every > 0 && k % late_every == late_every - 1;
      test::publish_drive_step(bus_, d, k, late);
      if (late) late_utimes_.push_back(d.utimes[k]);
      handle_all();
    }
    node.finish();
    handle_all();
    node.report_counters();
    key_poses_ = static_cast<int>(node.backend().key_poses().size());
    for (const KeyPose& k : node.backend().key_poses()) key_utimes_.push_back(k.utime);
  }
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }

  Bus bus_{"memq://"};
  std::map<std::string, double> counters_;
  std::vector<key_poses_t> messages_;
  std::vector<pose2d_t> trajectory_;
  std::vector<pose_graph_edges_t> edges_;
  std::vector<int64_t> key_utimes_;
  std::vector<int64_t> late_utimes_;
  int key_poses_ = 0;
};

// Poses flagged FLAG_LATE (a scan stamped late: where its points belong, not the base's pose at
// its stamp) are counted and left out: no key pose at them, and the graph's poses stay on the
// drive's.
TEST_F(BackendNodeTest, LatePosesAreCountedAndLeftOut) {
  run(BackendNodeConfig{}, 30.0, 7);
  ASSERT_FALSE(late_utimes_.empty());
  EXPECT_EQ(counters_.at("poses_late"), static_cast<double>(late_utimes_.size()));
  for (const int64_t t : late_utimes_) {
    EXPECT_EQ(std::count(key_utimes_.begin(), key_utimes_.end(), t), 0) << "key pose at " << t;
  }
  EXPECT_GT(key_poses_, 10);
}

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

// With the drift model the graph holds the drifting frontend's poses besides the key poses; the
// edges published name key poses only (before: graph vertex indices, twice the key pose ids,
// read as key ids by the annotator and past the end of the key poses by the node itself).
TEST_F(BackendNodeTest, PublishedEdgesNameKeyPosesOnlyWithTheDriftModel) {
  BackendNodeConfig config;
  // This frontend drifts by 3 % of the travel and 0.01 rad per metre.
  config.backend.frontend_drift_length_m = 1.0;
  config.backend.frontend_sigma_xy_m = 0.03;
  config.backend.frontend_sigma_theta_rad = 0.02;
  run(config, 18.0);
  ASSERT_GT(counters_.at("loop_closures"), 0.0);
  int expected_index = 0, frontend = 0, closures = 0;
  for (const pose_graph_edges_t& m : edges_) {
    EXPECT_EQ(m.first_index, expected_index);
    for (const pose_graph_edge_t& e : m.edges) {
      EXPECT_EQ(e.index, expected_index++);
      ASSERT_GE(e.from_id, 0);
      ASSERT_LT(e.to_id, key_poses_);
      EXPECT_LT(e.from_id, e.to_id);
      EXPECT_EQ(e.utime, key_utimes_[static_cast<std::size_t>(e.to_id)]);
      if (e.kind == pose_graph_edge_t::KIND_FRONTEND) {
        EXPECT_EQ(e.to_id, e.from_id + 1);
        ++frontend;
      }
      if (e.kind == pose_graph_edge_t::KIND_LOOP_CLOSURE) ++closures;
    }
  }
  EXPECT_EQ(frontend, key_poses_ - 1);  // one per key step
  EXPECT_EQ(closures, counters_.at("loop_closures"));
}

}  // namespace
}  // namespace traverse::backend
