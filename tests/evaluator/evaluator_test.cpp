#include "evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "config.hpp"
#include "synthetic.hpp"

namespace traverse::evaluator {
namespace {

using test::circle_pose;
using test::circle_truth;
using test::sample;

constexpr double kTol = 1e-9;

EvaluatorConfig config_with(const std::string& align) {
  EvaluatorConfig c;
  c.align = align;
  return c;
}

TEST(Evaluator, TruthAgainstItselfHasZeroError) {
  const Trajectory truth = circle_truth(30);
  for (const char* align : {"none", "first_pose", "se2"}) {
    const Evaluation ev = evaluate(truth, truth, config_with(align));
    EXPECT_EQ(ev.matched, truth.size()) << align;
    EXPECT_EQ(ev.unmatched, 0u);
    EXPECT_NEAR(ev.position_m.max, 0.0, kTol) << align;
    EXPECT_NEAR(ev.heading_rad.max, 0.0, kTol) << align;
    ASSERT_TRUE(ev.rpe_1m.rms_m && ev.rpe_10m.rms_m);
    EXPECT_NEAR(*ev.rpe_1m.rms_m, 0.0, kTol);
    EXPECT_NEAR(*ev.rpe_10m.rms_m, 0.0, kTol);
    EXPECT_NEAR(ev.max_jump.step_error_m, 0.0, kTol);
    EXPECT_NEAR(ev.duration_s, 30.0, 1e-12);
    EXPECT_NEAR(ev.length_m, 0.4 * 30.0, 1e-3);  // chords of a 12 m arc
  }
}

TEST(Evaluator, TranslationOffsetIsReportedExactly) {
  const Trajectory truth = circle_truth(20);
  Trajectory shifted = truth;
  shift(shifted, 0.3, -0.4, 0.0);
  const Evaluation ev = evaluate(shifted, truth, config_with("none"));
  EXPECT_NEAR(ev.position_m.rmse, 0.5, kTol);
  EXPECT_NEAR(ev.position_m.max, 0.5, kTol);
  EXPECT_NEAR(ev.position_m.sd, 0.0, 1e-7);
  EXPECT_NEAR(ev.heading_rad.max, 0.0, kTol);
  // A constant offset is no drift and no jump.
  EXPECT_NEAR(*ev.rpe_1m.rms_m, 0.0, kTol);
  EXPECT_NEAR(ev.max_jump.step_error_m, 0.0, kTol);
  // Tying the first poses together removes it.
  EXPECT_NEAR(evaluate(shifted, truth, config_with("first_pose")).position_m.max, 0.0, kTol);
}

TEST(Evaluator, HeadingOffsetIsReportedExactly) {
  const Trajectory truth = circle_truth(20);
  Trajectory turned = truth;
  shift(turned, 0.0, 0.0, 0.02);
  const Evaluation ev = evaluate(turned, truth, config_with("none"));
  EXPECT_NEAR(ev.heading_rad.rmse, 0.02, kTol);
  EXPECT_NEAR(ev.heading_rad.max, 0.02, kTol);
  EXPECT_NEAR(ev.heading_rad.sd, 0.0, 1e-7);
  EXPECT_NEAR(ev.position_m.max, 0.0, kTol);
  for (const ErrorSample& s : ev.samples) ASSERT_NEAR(s.heading_error_rad, 0.02, kTol);
}

TEST(Evaluator, HeadingErrorIsWrapped) {
  const Trajectory ref = {{0, Pose2(0, 0, M_PI - 0.01)}, {1000, Pose2(0, 0, M_PI - 0.01)}};
  const Trajectory est = {{0, Pose2(0, 0, -M_PI + 0.01)}, {1000, Pose2(0, 0, -M_PI + 0.01)}};
  const Evaluation ev = evaluate(est, ref, config_with("none"));
  EXPECT_NEAR(ev.heading_rad.max, 0.02, kTol);
  EXPECT_NEAR(ev.samples[0].heading_error_rad, 0.02, kTol);
}

TEST(Evaluator, EstimateBetweenReferenceSamplesIsInterpolated) {
  const Trajectory truth = circle_truth(20);
  // 20 Hz estimates halfway between the 200 Hz ground-truth samples.
  const Trajectory est = sample(circle_pose, 1'002'500, 50'000, 20 * 20);
  const Evaluation ev = evaluate(est, truth, config_with("none"));
  EXPECT_EQ(ev.matched, est.size());
  EXPECT_NEAR(ev.position_m.max, 0.0, 1e-9);
  EXPECT_NEAR(ev.heading_rad.max, 0.0, 1e-12);
  // A reference at 1 Hz: on a constant twist the SE(2) geodesic is exact, where interpolating
  // x and y linearly would be off by the chord's sag (L^2 / 8R = 2 mm for 0.4 m of a 10 m arc).
  const Trajectory sparse_ref = sample(circle_pose, 1'000'000, 1'000'000, 21);
  EvaluatorConfig c = config_with("none");
  c.match.max_reference_gap_us = 1'000'000;
  const Evaluation coarse = evaluate(est, sparse_ref, c);
  EXPECT_EQ(coarse.matched, est.size());
  EXPECT_NEAR(coarse.position_m.max, 0.0, 1e-9);
}

TEST(Evaluator, NoExtrapolationAndNoInterpolationAcrossGaps) {
  // Reference at 10 Hz with a 2 s hole between 1.5 s and 3.5 s.
  Trajectory ref = sample(circle_pose, 1'000'000, 100'000, 6);         // 1.0 .. 1.5 s
  const Trajectory tail = sample(circle_pose, 3'500'000, 100'000, 6);  // 3.5 .. 4.0 s
  ref.insert(ref.end(), tail.begin(), tail.end());
  Trajectory est;
  for (int64_t t_us : {900'000,       // before the reference: unmatched
                       1'250'000,     // inside: matched
                       1'530'000,     // 30 ms into the hole: within edge tolerance, matched
                       2'500'000,     // middle of the 2 s hole: unmatched
                       3'460'000,     // 40 ms before the hole ends: matched
                       3'500'000,     // on a sample: matched
                       4'000'000,     // last sample: matched
                       4'000'001}) {  // after: unmatched
    est.push_back({t_us, circle_pose(1e-6 * static_cast<double>(t_us))});
  }
  EvaluatorConfig c = config_with("none");
  c.match.max_reference_gap_us = 500'000;
  c.match.edge_tolerance_us = 50'000;
  const Evaluation ev = evaluate(est, ref, c);
  EXPECT_EQ(ev.matched, 5u);
  EXPECT_EQ(ev.unmatched, 3u);
  ASSERT_EQ(ev.samples.size(), 5u);
  EXPECT_EQ(ev.samples[1].utime, 1'530'000);
  // A threshold longer than the hole lets the middle estimate through.
  c.match.max_reference_gap_us = 2'000'000;
  EXPECT_EQ(evaluate(est, ref, c).matched, 6u);
}

TEST(Evaluator, RepeatedAndUnsortedTimesAreHandled) {
  Trajectory truth = circle_truth(5);
  Trajectory est = truth;
  std::reverse(est.begin(), est.end());
  est.push_back(est.front());  // a repeated time
  const Evaluation ev = evaluate(est, truth, config_with("none"));
  EXPECT_EQ(ev.estimate_poses, truth.size());
  EXPECT_EQ(ev.matched, truth.size());
  EXPECT_NEAR(ev.position_m.max, 0.0, kTol);
}

TEST(Evaluator, Se2AlignmentRecoversARigidMotion) {
  const Trajectory truth = circle_truth(30);
  const Pose2 T_est_ref(5.0, -3.0, 0.7);  // the estimator's own frame
  Trajectory est = truth;
  for (StampedPose& p : est) p.pose = T_est_ref * p.pose;
  EXPECT_GT(evaluate(est, truth, config_with("none")).position_m.max, 1.0);
  for (const char* align : {"first_pose", "se2"}) {
    const Evaluation ev = evaluate(est, truth, config_with(align));
    EXPECT_EQ(align_name(ev.alignment.used), align);
    EXPECT_NEAR(ev.position_m.max, 0.0, 1e-9) << align;
    EXPECT_NEAR(ev.heading_rad.max, 0.0, 1e-9) << align;
    const Eigen::Vector3d d = between(ev.alignment.T_ref_est, T_est_ref.inverse()).log();
    EXPECT_LT(d.norm(), 1e-9) << align;
  }
}

TEST(Evaluator, Se2AlignmentOfAStandingPlatformFallsBackToFirstPose) {
  const Trajectory still = {{0, Pose2(1, 2, 0.3)}, {1000, Pose2(1, 2, 0.3)}};
  const Trajectory est = {{0, Pose2(0, 0, 0)}, {1000, Pose2(0, 0, 0)}};
  const Evaluation ev = evaluate(est, still, config_with("se2"));
  EXPECT_EQ(ev.alignment.used, Align::kFirstPose);
  EXPECT_NEAR(ev.position_m.max, 0.0, kTol);
}

TEST(Evaluator, NothingMatchedGivesEmptyResult) {
  const Evaluation ev = evaluate(circle_truth(1), {}, EvaluatorConfig{});
  EXPECT_EQ(ev.matched, 0u);
  EXPECT_EQ(ev.unmatched, 201u);
  EXPECT_FALSE(ev.rpe_1m.rms_m);
}

TEST(EvaluatorConfig, ValidationNamesTheKey) {
  EvaluatorConfig c;
  EXPECT_FALSE(validate(c));
  load_config_text("align: se2\nmax_reference_gap_us: 20000\n", "test.yaml", c);
  EXPECT_EQ(c.align, "se2");
  EXPECT_EQ(c.match.max_reference_gap_us, 20000);
  c.align = "umeyama";
  ASSERT_TRUE(validate(c));
  EXPECT_NE(validate(c)->find("align"), std::string::npos);
  c.align = "none";
  c.match.max_reference_gap_us = 0;
  ASSERT_TRUE(validate(c));
  EXPECT_NE(validate(c)->find("max_reference_gap_us"), std::string::npos);
  EXPECT_THROW(load_config_text("allign: se2\n", "test.yaml", c), ConfigError);
}

TEST(EvaluatorConfig, ShippedConfigLoadsAndIsValid) {
  EvaluatorConfig c;
  load_config("configs/evaluator.yaml", c);
  EXPECT_FALSE(validate(c));
}

}  // namespace
}  // namespace traverse::evaluator
