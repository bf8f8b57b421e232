// The collector on a live bus (memq://, in process): the same results as from a log.
#include <gtest/gtest.h>

#include <cmath>

#include "bus.hpp"
#include "evaluator.hpp"
#include "messages.hpp"
#include "pose_collector.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::evaluator {
namespace {

class CollectorLive : public ::testing::Test {
 protected:
  CollectorLive() : bus_("memq://") {}

  void publish_truth() {
    for (const StampedPose& p : test::circle_truth(10)) {
      publish("POSE_GROUND_TRUTH", test::pose_message(p));
    }
  }

  template <class T>
  void publish(const std::string& channel, T msg) {
    bus_.publish(channel, msg);
    ++published_;
  }

  // memq delivers one queued message per handle().
  void deliver() {
    for (int i = 0; i < published_; ++i) ASSERT_TRUE(bus_.handle(0));
    published_ = 0;
  }

  Bus bus_;
  int published_ = 0;
};

TEST_F(CollectorLive, KeyPosesNewestPerIdAndClosures) {
  PoseCollector c("KEY_POSES", "POSE_GROUND_TRUTH", "KEY_POSES");
  c.subscribe(bus_);
  publish_truth();
  using test::key_pose;
  publish("KEY_POSES", test::key_poses(1, {key_pose(0, 2'000'000, 0.4), key_pose(1, 4'000'000)}));
  publish("KEY_POSES",
          test::key_poses(2, {key_pose(0, 2'000'000), key_pose(2, 6'000'000)},
                          {test::loop_closure(0, 2, 2'000'000, 6'000'000, Pose2()),
                           test::loop_closure(1, 2, 4'000'000, 6'000'000,
                                              Pose2(0.0, 0.0, 6 * 0.005))}));  // 6 sigma
  deliver();
  EXPECT_EQ(c.estimate_type(), EstimateType::kKeyPoses);
  EXPECT_EQ(c.estimate_size(), 3u);
  EXPECT_EQ(c.reference().size(), 2001u);
  EvaluatorConfig cfg;
  cfg.align = "none";
  const Evaluation ev = evaluate(c.estimate(), c.reference(), cfg);
  EXPECT_EQ(ev.matched, 3u);
  EXPECT_NEAR(ev.position_m.max, 0.0, 1e-9);  // the 0.4 m first estimate was replaced
  const ClosureEvaluation closures =
      check_closures(c.closures().closures(), c.reference(), cfg.match, cfg.false_closure_sigmas);
  EXPECT_EQ(closures.closures, 2u);
  EXPECT_EQ(closures.false_closures, 1u);
  EXPECT_EQ(closures.unmatched, 0u);
}

TEST_F(CollectorLive, DenseSegmentsNewestRevisionAndClosuresFromAnotherChannel) {
  PoseCollector c("DENSE_SEGMENTS", "POSE_GROUND_TRUTH", "KEY_POSES");
  c.subscribe(bus_);
  publish_truth();
  using test::dense_segment;
  publish("DENSE_SEGMENTS", test::dense_segments({dense_segment(0, 0, 1'000'000, 0.2)}));
  publish("DENSE_SEGMENTS", test::dense_segments({dense_segment(0, 2, 1'000'000, 0.0),
                                                  dense_segment(1, 0, 2'000'000, 0.0)}));
  publish("DENSE_SEGMENTS", test::dense_segments({dense_segment(0, 1, 1'000'000, 0.2)}));
  // The backend's closures, one far outside the ground truth's time span.
  publish("KEY_POSES", test::key_poses(1, {},
                                       {test::loop_closure(0, 1, 2'000'000, 3'000'000, Pose2()),
                                        test::loop_closure(1, 9, 3'000'000, 60'000'000, Pose2())}));
  deliver();
  EXPECT_EQ(c.estimate_type(), EstimateType::kDenseSegments);
  EXPECT_EQ(c.dense().size(), 2u);
  EXPECT_EQ(c.dense().stale(), 1u);
  const Trajectory estimate = c.estimate();
  EXPECT_EQ(estimate.size(), 41u);
  EvaluatorConfig cfg;
  cfg.align = "none";
  EXPECT_NEAR(evaluate(estimate, c.reference(), cfg).position_m.max, 0.0, 1e-9);
  const ClosureEvaluation closures =
      check_closures(c.closures().closures(), c.reference(), cfg.match, cfg.false_closure_sigmas);
  EXPECT_EQ(closures.closures, 2u);
  EXPECT_EQ(closures.unmatched, 1u);
  EXPECT_EQ(closures.false_closures, 0u);
}

TEST_F(CollectorLive, MixedTypesAreCountedAndDropped) {
  PoseCollector c("POSE_BACKEND", "POSE_GROUND_TRUTH", "KEY_POSES");
  c.subscribe(bus_);
  pose2d_t pose{};
  pose.utime = 2'000'000;
  publish("POSE_BACKEND", pose);
  publish("POSE_BACKEND", test::key_poses(1, {test::key_pose(0, 3'000'000)}));
  imu_t imu{};
  imu.utime = 3'000'000;
  publish("POSE_BACKEND", imu);
  publish("POSE_GROUND_TRUTH", imu);  // not a pose on the reference channel either
  deliver();
  EXPECT_EQ(c.estimate_type(), EstimateType::kPose2d);
  EXPECT_EQ(c.estimate().size(), 1u);
  EXPECT_EQ(c.mixed_type_messages(), 3u);
  EXPECT_EQ(c.estimate_types_seen().size(), 3u);
  EXPECT_TRUE(c.reference().empty());
}

TEST_F(CollectorLive, FrontendPosesAreCollectedBesideAnotherEstimate) {
  PoseCollector c("KEY_POSES", "POSE_GROUND_TRUTH", "KEY_POSES", "POSE_FRONTEND");
  c.subscribe(bus_);
  publish("KEY_POSES", test::key_poses(1, {test::key_pose(0, 2'000'000)}));
  pose2d_t pose{};
  pose.utime = 2'000'000;
  publish("POSE_FRONTEND", pose);
  pose.utime = 2'100'000;
  pose.x = std::nan("");
  publish("POSE_FRONTEND", pose);  // left out and counted
  imu_t imu{};
  imu.utime = 2'200'000;
  publish("POSE_FRONTEND", imu);  // not the frontend's type: not ours to judge
  deliver();
  EXPECT_EQ(c.estimate_type(), EstimateType::kKeyPoses);
  ASSERT_EQ(c.frontend().size(), 1u);
  EXPECT_EQ(c.frontend()[0].utime, 2'000'000);
  EXPECT_EQ(c.non_finite_poses(), 1u);
  EXPECT_EQ(c.mixed_type_messages(), 0u);
  // Without a frontend channel nothing is kept.
  PoseCollector none("KEY_POSES", "POSE_GROUND_TRUTH", "KEY_POSES");
  none.on_event("POSE_FRONTEND", nullptr, 0);
  EXPECT_TRUE(none.frontend().empty());
  EXPECT_EQ(none.decode_failures(), 0u);
}

}  // namespace
}  // namespace traverse::evaluator
