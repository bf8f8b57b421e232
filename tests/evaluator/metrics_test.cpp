#include "metrics.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "evaluator.hpp"
#include "synthetic.hpp"

namespace traverse::evaluator {
namespace {

// A straight line along x at 0.5 m/s; steps that are exact in binary keep the travel exact, so
// RPE pairs are exactly 1 m and 10 m apart.
Trajectory line(int n, double step_m) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    t.push_back({static_cast<int64_t>(i * step_m * 2e6), Pose2(i * step_m, 0.0, 0.0)});
  }
  return t;
}

EvaluatorConfig no_alignment() {
  EvaluatorConfig c;
  c.align = "none";
  return c;
}

TEST(EvaluatorErrorStats, RmseSdMax) {
  const ErrorStats s = error_stats({1.0, 3.0});
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(5.0));
  EXPECT_DOUBLE_EQ(s.sd, 1.0);  // population SD
  EXPECT_DOUBLE_EQ(s.max, 3.0);
  const ErrorStats empty = error_stats({});
  EXPECT_EQ(empty.rmse, 0.0);
}

TEST(EvaluatorRelativePoseError, ScaleDriftOfTwoPercent) {
  // The estimate travels 2 % too far: 0.02 m per metre, 0.2 m per 10 m, wherever it starts.
  const Trajectory truth = line(121, 0.25);  // 30 m in 60 s
  Trajectory est = truth;
  for (StampedPose& p : est) p.pose = Pose2(1.02 * p.pose.x(), 0.0, 0.0);
  const Evaluation ev = evaluate(est, truth, no_alignment());
  ASSERT_TRUE(ev.rpe_1m.rms_m && ev.rpe_10m.rms_m);
  EXPECT_NEAR(*ev.rpe_1m.rms_m, 0.02, 1e-12);
  EXPECT_NEAR(*ev.rpe_10m.rms_m, 0.2, 1e-12);
  EXPECT_EQ(ev.rpe_1m.pairs, 121u - 4u);  // every pose with 1 m of travel after it
  EXPECT_EQ(ev.rpe_10m.pairs, 121u - 40u);
  // The absolute error grows to 2 % of the 30 m; the steps are 5 mm too long each.
  EXPECT_NEAR(ev.position_m.max, 0.6, 1e-12);
  EXPECT_NEAR(ev.max_jump.step_error_m, 0.005, 1e-12);
  EXPECT_NEAR(ev.length_m, 30.0, 1e-12);
}

TEST(EvaluatorRelativePoseError, HeadingDriftBendsTheEstimate) {
  // A yaw-rate bias of 0.01 rad per metre: over d metres the relative error is the chord of an
  // arc of radius 100 m against the straight line (||(sin a, 1 - cos a) R - (d, 0)||, a = d/R).
  const Trajectory truth = line(481, 0.0625);  // 30 m
  Trajectory est;
  const double radius_m = 100.0;
  for (const StampedPose& p : truth) {
    const double a = p.pose.x() / radius_m;
    est.push_back({p.utime, Pose2(radius_m * std::sin(a), radius_m * (1 - std::cos(a)), a)});
  }
  const Evaluation ev = evaluate(est, truth, no_alignment());
  const auto expected = [&](double d) {
    const double a = d / radius_m;
    return std::hypot(radius_m * std::sin(a) - d, radius_m * (1 - std::cos(a)));
  };
  EXPECT_NEAR(*ev.rpe_1m.rms_m, expected(1.0), 1e-9);
  EXPECT_NEAR(*ev.rpe_10m.rms_m, expected(10.0), 1e-9);
  EXPECT_GT(*ev.rpe_10m.rms_m, 9.0 * *ev.rpe_1m.rms_m);  // grows with distance squared
}

TEST(EvaluatorRelativePoseError, ShortTrajectoryHasNoLongPairs) {
  const Trajectory truth = line(11, 0.25);  // 2.5 m
  const Evaluation ev = evaluate(truth, truth, no_alignment());
  EXPECT_TRUE(ev.rpe_1m.rms_m);
  EXPECT_FALSE(ev.rpe_10m.rms_m);
  EXPECT_EQ(ev.rpe_10m.pairs, 0u);
}

TEST(EvaluatorMaxJump, ALoopClosureJumpIsFoundWhereItHappens) {
  const Trajectory truth = test::circle_truth(20);
  Trajectory est = truth;
  const std::size_t k = 1500;
  // From pose k on the estimate is moved 0.3 m sideways and turned by 0.01 rad about pose k.
  const Pose2 correction = truth[k].pose * Pose2(0.0, 0.3, 0.01) * truth[k].pose.inverse();
  for (std::size_t i = k; i < est.size(); ++i) est[i].pose = correction * est[i].pose;
  const Evaluation ev = evaluate(est, truth, no_alignment());
  EXPECT_NEAR(ev.max_jump.step_error_m, 0.3, 1e-3);  // plus the 2 mm step turned by 0.01 rad
  EXPECT_EQ(ev.max_jump.index, k);
  EXPECT_EQ(ev.samples[ev.max_jump.index].utime, truth[k].utime);
  EXPECT_NEAR(ev.heading_rad.max, 0.01, 1e-9);
}

TEST(EvaluatorMaxJump, NoiseFreeTruthHasNoJump) {
  const Trajectory truth = test::circle_truth(5);
  EXPECT_NEAR(max_jump({truth[0].pose}, {truth[0].pose}).step_error_m, 0.0, 0.0);
  EXPECT_NEAR(evaluate(truth, truth, no_alignment()).max_jump.step_error_m, 0.0, 1e-12);
}

// Each pose given independent Gaussian errors (sigma 2 cm in x and y, 5 mrad in heading) and
// reporting exactly that covariance: the step NEES is chi-square with 2 degrees of freedom, median
// 1.39 and about 1 % above 9.21, whatever the frame the estimate is in (it is turned and moved
// here, and aligned back). Reporting a covariance 100 times too small is caught; none gives null.
TEST(EvaluatorStepConsistency, RightCovariancesGiveChiSquareNees) {
  const Trajectory truth = test::circle_truth(20);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double sxy = 0.02, sth = 0.005;
  const Pose2 frame(3.0, -2.0, 0.7);
  Trajectory est, optimistic, unknown;
  for (const StampedPose& t : truth) {
    StampedPose e = t;
    const Pose2 noisy(t.pose.x() + sxy * n01(rng), t.pose.y() + sxy * n01(rng),
                      t.pose.theta() + sth * n01(rng));
    e.pose = frame * noisy;
    Eigen::Matrix3d c = Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal();
    Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
    A.topLeftCorner<2, 2>() = frame.rotation();
    e.covariance = A * c * A.transpose();  // in the estimate's frame
    est.push_back(e);
    e.covariance /= 100.0;
    optimistic.push_back(e);
    e.covariance.setZero();
    unknown.push_back(e);
  }
  const Evaluation ev = evaluate(est, truth, EvaluatorConfig{});  // aligned on the first pose
  ASSERT_GT(ev.step_consistency.steps, 3000u);
  std::printf("steps %zu, NEES median %.3f, outside 99 %% %.4f\n", ev.step_consistency.steps,
              *ev.step_consistency.nees_median, *ev.step_consistency.outside_99_fraction);
  // First-pose alignment moves every pose by the first one's error: steps are unaffected.
  EXPECT_NEAR(*ev.step_consistency.nees_median, 1.39, 0.15);
  EXPECT_NEAR(*ev.step_consistency.outside_99_fraction, 0.01, 0.006);
  const Evaluation bad = evaluate(optimistic, truth, EvaluatorConfig{});
  EXPECT_GT(*bad.step_consistency.nees_median, 100.0);
  EXPECT_GT(*bad.step_consistency.outside_99_fraction, 0.9);
  const Evaluation none = evaluate(unknown, truth, EvaluatorConfig{});
  EXPECT_EQ(none.step_consistency.steps, 0u);
  EXPECT_FALSE(none.step_consistency.nees_median.has_value());
}

}  // namespace
}  // namespace traverse::evaluator
