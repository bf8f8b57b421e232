// Seed 004's loop closure, on the court: logs/court-loop_seed1_graph.lcmlog holds the backend's
// and the annotator's messages of a whole court-loop run (realistic profile, seed 1; see
// logs/README.md). After each loop closure the key poses near it must get smaller bounds and some
// of them a better level and another colour in the annotations the run recorded (covariance scale
// 1), and smaller bounds in those the annotator computes now from the same backend messages with
// configs/annotator.yaml.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "annotator_node.hpp"
#include "config.hpp"
#include "lcm_log.hpp"

namespace traverse::annotator {
namespace {

const char* const kLog = "logs/court-loop_seed1_graph.lcmlog";
constexpr double kNearM = 10.0;  // [m] key poses this close to a closure's key poses

template <class T>
bool decode(const LogEvent& e, T& msg) {
  return msg.decode(e.data.data(), 0, static_cast<int>(e.data.size())) ==
         static_cast<int>(e.data.size());
}

// Follows the key poses and annotations in order and scores every loop-closure update.
struct ClosureScore {
  std::map<int64_t, Eigen::Vector2d> position;  // newest key pose positions
  std::map<int64_t, key_annotation_t> now;      // newest annotations
  std::vector<int64_t> closure_ids;             // key poses of closures not yet scored
  int updates = 0, near = 0, lowered = 0, raised = 0, recoloured = 0, greener = 0;

  void on_key_poses(const key_poses_t& m) {
    for (const key_pose_t& k : m.poses) position[k.id] = {k.x, k.y};
    for (const loop_closure_t& c : m.closures) {
      closure_ids.push_back(c.from_id);
      closure_ids.push_back(c.to_id);
    }
  }
  void on_annotations(const annotations_t& m) {
    const bool closure = m.reason == annotations_t::REASON_LOOP_CLOSURE && !closure_ids.empty();
    if (closure && m.part == 0) ++updates;
    for (const key_annotation_t& k : m.keys) {
      auto before = now.find(k.id);
      if (closure && before != now.end() && is_near(k.id)) {
        ++near;
        if (k.bound_m < before->second.bound_m) ++lowered;
        if (k.bound_m > before->second.bound_m) ++raised;
        if (k.rgb[0] != before->second.rgb[0] || k.rgb[1] != before->second.rgb[1]) {
          ++recoloured;
          if (k.level < before->second.level) ++greener;
        }
      }
      now[k.id] = k;
    }
    if (closure && m.part + 1 == m.parts) closure_ids.clear();
  }
  bool is_near(int64_t id) const {
    for (int64_t c : closure_ids) {
      auto a = position.find(id), b = position.find(c);
      if (a != position.end() && b != position.end() && (a->second - b->second).norm() < kNearM) {
        return true;
      }
    }
    return false;
  }
};

void expect_closures_lower_bounds(const ClosureScore& s, bool expect_new_colours = true) {
  std::printf(
      "closure updates %d: key poses near a closure %d, bound lowered %d, raised %d, "
      "recoloured %d (greener %d)\n",
      s.updates, s.near, s.lowered, s.raised, s.recoloured, s.greener);
  EXPECT_GT(s.updates, 0);
  EXPECT_GT(s.near, 20);
  EXPECT_GT(s.lowered, 4 * s.raised) << "lowered " << s.lowered << ", raised " << s.raised;
  if (expect_new_colours) {
    EXPECT_GT(s.greener, 0) << "recoloured " << s.recoloured;
  }
}

TEST(CourtClosure, RecordedAnnotationsDropAndTurnGreenerAtClosures) {
  LogReader reader(kLog);
  ClosureScore score;
  int annotations = 0;
  while (auto e = reader.next()) {
    if (e->channel == "KEY_POSES") {
      key_poses_t m;
      ASSERT_TRUE(decode(*e, m));
      score.on_key_poses(m);
    } else if (e->channel == "ANNOTATIONS") {
      annotations_t m;
      ASSERT_TRUE(decode(*e, m));
      score.on_annotations(m);
      ++annotations;
    }
  }
  EXPECT_TRUE(reader.damage().empty());
  ASSERT_GT(annotations, 100);
  expect_closures_lower_bounds(score);
}

// With the shipped covariance_scale the bounds near the closures must drop; the colours need not
// change (the log's marginals are the raw ones of an older backend, which configs/backend.yaml no
// longer publishes, so the levels say nothing here).
TEST(CourtClosure, AnnotatorWithTheShippedConfigLowersTheBounds) {
  AnnotatorNodeConfig config;
  load_config("configs/annotator.yaml", config);
  ASSERT_FALSE(validate(config));
  config.annotations_channel = "ANNOTATIONS_NOW";
  Bus bus("memq://");
  AnnotatorNode node(bus, config);
  ClosureScore score;
  bus.subscribe<key_poses_t>(
      "KEY_POSES", [&](const key_poses_t& m) { score.on_key_poses(m); }, true);
  bus.subscribe<annotations_t>(
      "ANNOTATIONS_NOW", [&](const annotations_t& m) { score.on_annotations(m); }, true);
  LogReader reader(kLog);
  while (auto e = reader.next()) {
    if (e->channel != "KEY_POSES" && e->channel != "POSE_GRAPH_EDGES") continue;
    bus.lcm().publish(e->channel, e->data.data(), static_cast<unsigned>(e->data.size()));
    while (bus.lcm().handleTimeout(0) > 0) {
    }
  }
  expect_closures_lower_bounds(score, /*expect_new_colours=*/false);
}

}  // namespace
}  // namespace traverse::annotator
