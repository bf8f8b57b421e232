// The annotator behind the backend on memq://: the graph the annotator rebuilds from
// POSE_GRAPH_EDGES and KEY_POSES gives the backend's own marginals (so no edge is missing), the
// annotations carry the legend, and a loop closure lowers the bounds near it and changes colours.
#include "annotator_node.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <functional>
#include <map>
#include <set>

#include "backend_node.hpp"
#include "drive_feed.hpp"
#include "resend.hpp"
#include "traverse/key_poses_t.hpp"

namespace traverse::annotator {
namespace {

class AnnotatorNodeTest : public ::testing::Test {
 protected:
  // The backend's drive round an ellipse with loop closures (tests/backend_slam), both nodes on
  // one in-process bus.
  void run(AnnotatorNodeConfig config) {
    backend::BackendNodeConfig backend_config;
    backend_config.max_poses_per_message = 10;  // parts for both channels
    backend_config.backend.frontend_sigma_xy_m = 0.015;
    backend_config.backend.frontend_sigma_theta_rad = 0.005;
    ASSERT_FALSE(backend::validate(backend_config));
    ASSERT_FALSE(validate(config));
    backend::BackendNode backend(bus_, backend_config);
    AnnotatorNode annotator(bus_, config,
                            [this](const std::string& k, double v) { counters_[k] = v; });
    bus_.subscribe<annotations_t>(
        channels::kAnnotations, [this](const annotations_t& m) { messages_.push_back(m); }, true);
    bus_.subscribe<pose_graph_edges_t>(
        channels::kPoseGraphEdges, [this](const pose_graph_edges_t& m) { edges_.push_back(m); },
        true);
    bus_.subscribe<annotations_t>(
        channels::full_channel(channels::kAnnotations),
        [this](const annotations_t& m) { full_.push_back(m); }, true);
    const backend::test::Drive d = backend::test::drive_ellipse(18.0);
    for (std::size_t k = 0; k < d.utimes.size(); ++k) {
      backend::test::publish_drive_step(bus_, d, k);
      handle_all();
      if (on_step_) on_step_(annotator);
    }
    if (ask_) {  // a listener that started late, before the end of data
      const std::size_t before = messages_.size();
      request_resend(bus_, "test", {channels::kAnnotations});
      handle_all();
      annotated_when_asked_ = annotator.annotator().annotations().size();
      answer_on_incremental_ = messages_.size() - before;
    }
    backend.finish();
    handle_all();
    annotator.finish();
    handle_all();
    annotator.report_counters();
    const auto& keys = backend.backend().key_poses();
    for (const auto& k : keys) backend_marginals_.push_back(k.covariance);
    backend_poses_ = backend.backend().graph().poses;
    backend_edges_ = backend.backend().graph().edges.size();
    closures_ = backend.backend().closures().size();
  }
  void handle_all() {
    while (bus_.lcm().handleTimeout(0) > 0) {
    }
  }

  Bus bus_{"memq://"};
  std::map<std::string, double> counters_;
  std::vector<annotations_t> messages_;
  std::vector<pose_graph_edges_t> edges_;
  std::vector<Eigen::Matrix3d> backend_marginals_;
  std::vector<Pose2> backend_poses_;
  std::size_t backend_edges_ = 0, closures_ = 0;
  bool ask_ = false;
  std::function<void(const AnnotatorNode&)> on_step_;  // after each step of the drive
  std::vector<annotations_t> full_;  // the answer to a late listener (ANNOTATIONS_FULL)
  std::size_t annotated_when_asked_ = 0, answer_on_incremental_ = 0;
};

// A listener that starts late asks for every annotation and gets them all on ANNOTATIONS_FULL,
// with the legend, and nothing more on ANNOTATIONS.
TEST_F(AnnotatorNodeTest, ALateListenerGetsEveryAnnotation) {
  ask_ = true;
  run(AnnotatorNodeConfig{});
  ASSERT_GT(annotated_when_asked_, 10u);
  std::set<int64_t> ids;
  for (const annotations_t& m : full_) {
    EXPECT_EQ(m.n_levels, 5);
    EXPECT_EQ(m.parts, static_cast<int32_t>(full_.size()));
    for (const key_annotation_t& k : m.keys) ids.insert(k.id);
  }
  EXPECT_EQ(ids.size(), annotated_when_asked_);
  EXPECT_EQ(answer_on_incremental_, 0u);
  EXPECT_EQ(counters_.at("resend_answers"), 1.0);
}

// Requests are paced by key pose time (common/resend.hpp): a burst from one requester gets one
// answer per resend.pace_s (5 s by default), and a requester not answered yet is answered inside
// that stretch. The data time is the newest ANNOTATIONS message's (the annotator's newest key
// pose).
TEST_F(AnnotatorNodeTest, ABurstGetsOneAnswerPerStretchAndANewRequesterIsAnswered) {
  const auto answers = [this] {
    return std::count_if(full_.begin(), full_.end(),
                         [](const annotations_t& m) { return m.part == 0; });
  };
  const auto ask = [this](const std::string& who) {
    request_resend(bus_, who, {channels::kAnnotations});
    handle_all();
  };
  int64_t answered_at = -1;  // [us] data time of the first answer
  int step = 0;
  on_step_ = [&](const AnnotatorNode& node) {
    if (node.annotator().annotations().size() < 5 || messages_.empty()) return;
    const int64_t now = messages_.back().utime;
    if (step == 0) {
      for (int k = 0; k < 4; ++k) ask("viewer");
      EXPECT_EQ(answers(), 1);
      ask("mapper");  // not answered yet
      EXPECT_EQ(answers(), 2);
      answered_at = now;
      step = 1;
    } else if (step == 1 && now - answered_at >= 2'000'000) {
      ask("viewer");  // inside its stretch
      EXPECT_EQ(answers(), 2);
      step = 2;
    } else if (step == 2 && now - answered_at >= 6'000'000) {
      ask("viewer");
      EXPECT_EQ(answers(), 3);
      step = 3;
    }
  };
  run(AnnotatorNodeConfig{});
  EXPECT_EQ(step, 3);  // the drive was long enough for every step
  EXPECT_EQ(counters_.at("resend_requests"), 7.0);
  EXPECT_EQ(counters_.at("resend_answers"), 3.0);
  EXPECT_EQ(counters_.at("resend_requests_paced"), 4.0);
}

TEST_F(AnnotatorNodeTest, RebuildsTheBackendsGraphAndCoversEveryKeyPose) {
  AnnotatorNodeConfig config;
  run(config);
  ASSERT_GT(closures_, 0u);
  // Every edge once, in order, in parts of at most 10.
  int next = 0;
  for (const pose_graph_edges_t& m : edges_) {
    EXPECT_LE(m.n_edges, 10);
    EXPECT_EQ(m.first_index, next);
    for (const pose_graph_edge_t& e : m.edges) {
      EXPECT_EQ(e.index, next++);
      EXPECT_EQ(e.kind == pose_graph_edge_t::KIND_LOOP_CLOSURE, e.to_id != e.from_id + 1);
    }
  }
  EXPECT_EQ(next, static_cast<int>(backend_edges_));
  EXPECT_EQ(counters_.at("edges"), static_cast<double>(backend_edges_));
  EXPECT_EQ(counters_.at("edges_missed"), 0.0);
  EXPECT_EQ(counters_.at("local_failed"), 0.0);
  // The last message (end of data) holds every key pose, with the legend.
  const annotations_t& last = messages_.back();
  EXPECT_EQ(last.reason, static_cast<int8_t>(annotations_t::REASON_FINAL));
  EXPECT_EQ(last.standard, "USIBD LOA");
  ASSERT_EQ(last.n_levels, 5);
  EXPECT_EQ(last.levels[0].name, "LOA50");
  EXPECT_EQ(last.coloured_by, "absolute");
  EXPECT_EQ(last.bound_method, "exact");
  EXPECT_DOUBLE_EQ(last.confidence, 0.95);
  std::size_t keys = 0;
  for (auto it = messages_.rbegin(); it != messages_.rend() && it->reason == last.reason; ++it) {
    keys += it->keys.size();
  }
  EXPECT_EQ(keys, backend_marginals_.size());
  for (const annotations_t& m : messages_) {
    for (const key_annotation_t& k : m.keys) {
      ASSERT_GE(k.level, 0);
      ASSERT_LT(k.level, m.n_levels);
      EXPECT_EQ(k.rgb[0], m.levels[k.level].rgb[0]);
      EXPECT_EQ(k.rgb[1], m.levels[k.level].rgb[1]);
      EXPECT_GE(k.local_bound_m, 0.0);
    }
  }
}

TEST_F(AnnotatorNodeTest, EdgeMessagesRebuildTheBackendsInformationMatrix) {
  // With the paper's bound the absolute bound is 2 sqrt(lambda_max) of the marginal as last sent.
  AnnotatorNodeConfig config;
  config.annotator.bound = "paper";
  config.annotator.republish_fraction = 0.0;
  run(config);
  // The graph from the edge messages at the backend's final poses: the backend's own marginals.
  backend::PoseGraph graph;
  for (std::size_t i = 0; i < backend_poses_.size(); ++i) {
    graph.add_vertex(static_cast<int64_t>(i), backend_poses_[i], i == 0);
  }
  for (const pose_graph_edges_t& m : edges_) {
    for (const pose_graph_edge_t& e : m.edges) {
      backend::Edge edge;
      edge.from = static_cast<int>(e.from_id);
      edge.to = static_cast<int>(e.to_id);
      edge.T_from_to = Pose2(e.x, e.y, e.theta);
      for (int k = 0; k < 9; ++k) edge.information(k / 3, k % 3) = e.information[k];
      graph.edges.push_back(edge);
    }
  }
  JointCovariance joint;
  ASSERT_TRUE(joint.factor(graph));
  std::map<int64_t, double> bound;
  for (const annotations_t& m : messages_) {
    for (const key_annotation_t& k : m.keys) bound[k.id] = k.bound_m;
  }
  ASSERT_EQ(bound.size(), backend_marginals_.size());
  for (std::size_t i = 1; i < backend_marginals_.size(); ++i) {
    EXPECT_TRUE(joint.marginal(static_cast<int>(i)).isApprox(backend_marginals_[i], 1e-6)) << i;
    // The backend resends a key pose when a variance changed by 1 % (backend_node.hpp).
    const Eigen::Matrix2d c = backend_marginals_[i].topLeftCorner<2, 2>();
    const double expected = 2.0 * std::sqrt(c.eigenvalues().real().maxCoeff());
    EXPECT_NEAR(bound[static_cast<int64_t>(i)], expected, 0.01 * expected) << i;
  }
}

TEST_F(AnnotatorNodeTest, LoopClosureLowersBoundsAndChangesColours) {
  AnnotatorNodeConfig config;
  // Levels 15 mm apart so that this short drive (bounds of 20 to 70 mm) spans several of them.
  config.annotator.limits_m = {0.015, 0.03, 0.045, 0.06};
  config.annotator.best_level = "LOA40";
  config.annotator.worst_level = "LOA10";
  run(config);
  std::map<int64_t, key_annotation_t> now;
  int closure_messages = 0, lowered = 0, recoloured = 0;
  for (const annotations_t& m : messages_) {
    if (m.reason == annotations_t::REASON_LOOP_CLOSURE) {
      ++closure_messages;
      for (const key_annotation_t& k : m.keys) {
        auto it = now.find(k.id);
        if (it == now.end()) continue;
        if (k.bound_m < it->second.bound_m) ++lowered;
        if (k.level < it->second.level && k.rgb[1] > it->second.rgb[1]) ++recoloured;
      }
    }
    for (const key_annotation_t& k : m.keys) now[k.id] = k;
  }
  EXPECT_GT(closure_messages, 0);
  EXPECT_GT(lowered, 5);
  EXPECT_GT(recoloured, 0);  // greener after the closure
  EXPECT_GT(counters_.at("level_changes"), 0.0);
}

}  // namespace
}  // namespace traverse::annotator
