// The coverage evaluation on synthetic runs whose errors are drawn from known covariances.
#include "coverage.hpp"

#include <gtest/gtest.h>

#include <random>

#include "bounds.hpp"

namespace traverse::annotator {
namespace {

// Key poses along a line whose true positions are off by errors drawn from `true_scale` times
// the covariance the key poses claim; the ground truth is moved by a rigid transform, which the
// alignment at the first key pose must undo.
struct SyntheticRun {
  std::vector<KeyRecord> keys;
  std::vector<StampedTruth> truth;
};

SyntheticRun make_run(double true_scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  const Pose2 T_truth_world(10.0, -3.0, 0.8);  // the truth's own frame
  SyntheticRun run;
  for (int i = 0; i < 4000; ++i) {
    const int64_t utime = 100000 * i;
    const Pose2 T_true(0.2 * i, 0.0, 0.0);
    KeyRecord k;
    k.id = i;
    k.utime = utime;
    const double sx = 0.001 * (1 + i % 5), sy = 0.0005 * (1 + i % 3);
    k.covariance = Eigen::Vector3d(sx * sx, sy * sy, 1e-6).asDiagonal();
    Eigen::Vector2d e = Eigen::Vector2d(sx * n01(rng), sy * n01(rng)) * std::sqrt(true_scale);
    if (i == 0) e.setZero();
    k.T_world_base = Pose2(T_true.x() + e.x(), T_true.y() + e.y(), 0.0);
    k.bound_m = bound_95(true_scale * k.covariance.topLeftCorner<2, 2>(), BoundMethod::kExact);
    k.level = i % 5 >= 3 ? 1 : 0;  // the key poses with the larger sigma in x
    k.points_base = {Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(0.0, 2.0)};
    run.keys.push_back(k);
    run.truth.push_back({utime, T_truth_world * T_true});
  }
  return run;
}

TEST(Coverage, ConsistentBoundsCoverNinetyFivePercentAndNeesIsTwo) {
  const SyntheticRun run = make_run(1.0, 3);
  const CoverageResult r = evaluate_coverage(run.keys, run.truth, 0.0);
  EXPECT_EQ(r.key_poses, 3999);
  EXPECT_NEAR(r.coverage, 0.95, 0.012);  // binomial SD 0.0034
  EXPECT_NEAR(r.nees_mean, 2.0, 0.15);
  EXPECT_NEAR(r.scale_by_mean, 1.0, 0.08);
  EXPECT_NEAR(r.scale_by_q95, 1.0, 0.1);
}

TEST(Coverage, NeesFindsTheScaleOfOverConfidentCovariances) {
  SyntheticRun run = make_run(16.0, 4);
  // The published bounds come from the raw covariances: far too small.
  for (KeyRecord& k : run.keys) {
    k.bound_m = bound_95(k.covariance.topLeftCorner<2, 2>(), BoundMethod::kExact);
  }
  const CoverageResult r = evaluate_coverage(run.keys, run.truth, 0.0);
  EXPECT_LT(r.coverage, 0.6);
  EXPECT_NEAR(r.scale_by_mean, 16.0, 1.5);
  EXPECT_NEAR(r.scale_by_q95, 16.0, 2.0);
  // The scale at which 95 % lie inside the published radius: the same for Gaussian errors.
  EXPECT_NEAR(r.scale_by_coverage, 16.0, 2.0);
  ASSERT_EQ(r.needed_scale.size(), 3999u);
  int inside_at_16 = 0;
  for (double s : r.needed_scale) inside_at_16 += s <= 16.0;
  EXPECT_NEAR(inside_at_16 / 3999.0, 0.95, 0.015);
}

TEST(Coverage, TruthInterpolatesAndLevelsReportPointErrors) {
  const std::vector<StampedTruth> truth = {{0, Pose2(0, 0, 0)}, {10, Pose2(1, 0, 0)}};
  EXPECT_NEAR(truth_at(truth, 5)->x(), 0.5, 1e-12);
  EXPECT_FALSE(truth_at(truth, 11));
  EXPECT_FALSE(truth_at(truth, -1));
  const SyntheticRun run = make_run(1.0, 5);
  const CoverageResult r = evaluate_coverage(run.keys, run.truth, 0.0);
  ASSERT_EQ(r.levels.size(), 2u);
  EXPECT_EQ(r.levels[1].points, 2 * r.levels[1].key_poses);
  EXPECT_GT(r.levels[1].mean_point_error_m, 1.5 * r.levels[0].mean_point_error_m);
  EXPECT_TRUE(r.levels_increasing);
  // The same run with the levels swapped: the claim fails.
  SyntheticRun swapped = run;
  for (KeyRecord& k : swapped.keys) k.level = 1 - k.level;
  EXPECT_FALSE(evaluate_coverage(swapped.keys, swapped.truth, 0.0).levels_increasing);
}

}  // namespace
}  // namespace traverse::annotator
