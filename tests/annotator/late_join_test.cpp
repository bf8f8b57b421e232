// An annotator that starts after the backend (memq://): it asks for the whole graph
// (resend_request_t naming KEY_POSES and POSE_GRAPH_EDGES), the backend answers on
// KEY_POSES_FULL / POSE_GRAPH_EDGES_FULL, and the late annotator ends with the same
// bounds, local ones included, as one that was there from the start. Without the request it ends
// with key poses it never heard of and no local bounds.
#include <gtest/gtest.h>

#include <map>
#include <memory>

#include "annotator_node.hpp"
#include "backend_node.hpp"
#include "drive_feed.hpp"

namespace traverse::annotator {
namespace {

struct Result {
  std::map<int64_t, Annotation> early, late, second_late;
  std::map<std::string, double> early_counters, late_counters, backend_counters;
  std::size_t key_poses = 0;
  int full_key_pose_messages = 0;
};

// The ellipse drive of tests/backend_slam; the late annotator (and a second one, if asked) starts
// at `join` of the drive.
Result run(double join, bool late_asks, bool second = false) {
  Bus bus("memq://");
  Result r;
  backend::BackendNodeConfig backend_config;
  backend_config.max_poses_per_message = 10;  // answers in several parts
  backend_config.backend.frontend_sigma_xy_m = 0.015;
  backend_config.backend.frontend_sigma_theta_rad = 0.005;
  backend::BackendNode backend(bus, backend_config,
                               [&](const std::string& k, double v) { r.backend_counters[k] = v; });
  AnnotatorNodeConfig early_config;
  early_config.annotator.republish_fraction = 0.0;  // every recomputed annotation is kept
  early_config.ask_for_state = false;               // there from the start: never asks
  AnnotatorNodeConfig late_config = early_config;
  late_config.annotations_channel = "ANNOTATIONS_LATE";
  late_config.ask_for_state = late_asks;
  AnnotatorNode early(bus, early_config,
                      [&](const std::string& k, double v) { r.early_counters[k] = v; });
  std::unique_ptr<AnnotatorNode> late, second_late;
  bus.subscribe<key_poses_t>(
      channels::full_channel(channels::kKeyPoses),
      [&](const key_poses_t&) { ++r.full_key_pose_messages; }, true);
  const auto handle_all = [&] {
    while (bus.lcm().handleTimeout(0) > 0) {
    }
  };
  const backend::test::Drive d = backend::test::drive_ellipse(18.0);
  const auto join_step = static_cast<std::size_t>(join * static_cast<double>(d.utimes.size()));
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    if (k == join_step) {
      late = std::make_unique<AnnotatorNode>(
          bus, late_config, [&](const std::string& n, double v) { r.late_counters[n] = v; });
      AnnotatorNodeConfig second_config = late_config;
      second_config.annotations_channel = "ANNOTATIONS_SECOND";
      if (second) second_late = std::make_unique<AnnotatorNode>(bus, second_config);
    }
    backend::test::publish_drive_step(bus, d, k);
    handle_all();
  }
  backend.finish();
  handle_all();
  early.report_counters();
  late->report_counters();
  backend.report_counters();
  r.early = early.annotator().annotations();
  r.late = late->annotator().annotations();
  if (second_late) r.second_late = second_late->annotator().annotations();
  r.key_poses = backend.backend().key_poses().size();
  return r;
}

TEST(AnnotatorLateJoin, AsksForTheGraphAndEndsWithTheSameBounds) {
  const Result r = run(0.5, true);
  ASSERT_GT(r.key_poses, 20u);
  EXPECT_EQ(r.backend_counters.at("resend_requests"), r.late_counters.at("resend_requests_sent"));
  EXPECT_GE(r.backend_counters.at("resend_answers"), 1.0);
  EXPECT_GT(r.full_key_pose_messages, 1);  // the answer in parts of 10 key poses
  EXPECT_EQ(r.late_counters.at("edges"), r.early_counters.at("edges"));
  EXPECT_EQ(r.late_counters.at("local_failed"), 0.0);
  ASSERT_EQ(r.late.size(), r.key_poses);
  ASSERT_EQ(r.early.size(), r.key_poses);
  double worst_absolute = 0.0, worst_local = 0.0;
  for (const auto& [id, e] : r.early) {
    const Annotation& l = r.late.at(id);
    ASSERT_GE(l.local_bound_m, 0.0) << id;
    ASSERT_GE(e.local_bound_m, 0.0) << id;
    worst_absolute = std::max(worst_absolute, std::abs(l.bound_m - e.bound_m) / e.bound_m);
    if (e.local_bound_m > 0.0) {
      worst_local =
          std::max(worst_local, std::abs(l.local_bound_m - e.local_bound_m) / e.local_bound_m);
    }
    EXPECT_EQ(l.level, e.level) << id;
  }
  RecordProperty("worst_absolute_relative", std::to_string(worst_absolute));
  RecordProperty("worst_local_relative", std::to_string(worst_local));
  EXPECT_LT(worst_absolute, 1e-9);
  EXPECT_LT(worst_local, 1e-9);
}

TEST(AnnotatorLateJoin, TwoListenersAskingAtOnceGetOneAnswer) {
  const Result r = run(0.5, true, true);
  EXPECT_EQ(r.backend_counters.at("resend_requests"), 2.0);
  EXPECT_EQ(r.backend_counters.at("resend_answers"), 1.0);  // resend.pace_s apart at most
  ASSERT_EQ(r.second_late.size(), r.key_poses);
  for (const auto& [id, a] : r.second_late) {
    EXPECT_NEAR(a.local_bound_m, r.late.at(id).local_bound_m, 1e-12) << id;
  }
}

TEST(AnnotatorLateJoin, WithoutAskingItMissesKeyPosesAndLocalBounds) {
  const Result r = run(0.5, false);
  EXPECT_EQ(r.backend_counters.at("resend_answers"), 0.0);
  EXPECT_GT(r.late_counters.at("edges_missed"), 0.0);
  int without_local = 0;
  for (const auto& [id, l] : r.late) without_local += l.local_bound_m < 0.0;
  EXPECT_GT(without_local + static_cast<int>(r.key_poses - r.late.size()), 0);
}

}  // namespace
}  // namespace traverse::annotator
