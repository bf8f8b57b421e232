#include "loop_closures.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "synthetic.hpp"

namespace traverse::evaluator {
namespace {

using test::circle_pose;
using test::circle_truth;

constexpr double kSigmaXM = 0.01, kSigmaYM = 0.02, kSigmaThetaRad = 0.005;

// A closure between the truth at two times whose error e = t2v(Z^-1 T_true) is exactly `error`
// (Z = T_true * E^-1), with a diagonal covariance of the sigmas above.
LoopClosure closure(int64_t from_id, int64_t to_id, int64_t from_us, int64_t to_us,
                    const Pose2& error = Pose2()) {
  LoopClosure c;
  c.from_id = from_id;
  c.to_id = to_id;
  c.from_utime = from_us;
  c.to_utime = to_us;
  const Pose2 T_true = between(circle_pose(1e-6 * static_cast<double>(from_us)),
                               circle_pose(1e-6 * static_cast<double>(to_us)));
  c.T_from_to = T_true * error.inverse();
  c.covariance.diagonal() << kSigmaXM * kSigmaXM, kSigmaYM * kSigmaYM,
      kSigmaThetaRad * kSigmaThetaRad;
  return c;
}

constexpr double kFive = 5.0;

TEST(LoopClosures, ExactClosureIsTrue) {
  // 1.5 s and 18.25 s: between ground-truth samples, so interpolation is exercised too.
  const ClosureEvaluation ev =
      check_closures({closure(3, 40, 1'502'500, 18'250'000)}, circle_truth(20), {}, kFive);
  ASSERT_EQ(ev.checks.size(), 1u);
  EXPECT_EQ(ev.closures, 1u);
  EXPECT_EQ(ev.false_closures, 0u);
  EXPECT_EQ(ev.unmatched, 0u);
  ASSERT_TRUE(ev.max_mahalanobis && ev.rms_error_m && ev.max_error_m);
  EXPECT_NEAR(*ev.max_mahalanobis, 0.0, 1e-6);
  EXPECT_NEAR(*ev.max_error_m, 0.0, 1e-9);
  EXPECT_FALSE(ev.checks[0].is_false);
}

TEST(LoopClosures, SixSigmaOffIsFalseFourSigmaIsNot) {
  const std::vector<LoopClosure> closures = {
      closure(1, 30, 2'000'000, 15'000'000, Pose2(6 * kSigmaXM, 0.0, 0.0)),        // 6 sigma x
      closure(2, 31, 3'000'000, 16'000'000, Pose2(0.0, 0.0, 6 * kSigmaThetaRad)),  // 6 sigma theta
      closure(3, 32, 4'000'000, 17'000'000, Pose2(0.0, 4 * kSigmaYM, 0.0)),        // 4 sigma y
  };
  const ClosureEvaluation ev = check_closures(closures, circle_truth(20), {}, kFive);
  EXPECT_EQ(ev.false_closures, 2u);
  ASSERT_EQ(ev.checks.size(), 3u);
  EXPECT_TRUE(ev.checks[0].is_false);
  EXPECT_TRUE(ev.checks[1].is_false);
  EXPECT_FALSE(ev.checks[2].is_false);
  EXPECT_NEAR(*ev.checks[0].mahalanobis, 6.0, 1e-6);
  EXPECT_NEAR(*ev.checks[1].mahalanobis, 6.0, 1e-6);
  EXPECT_NEAR(*ev.checks[2].mahalanobis, 4.0, 1e-6);
  // The error is expressed in Z's frame, component by component.
  EXPECT_NEAR(ev.checks[0].error.x(), 6 * kSigmaXM, 1e-9);
  EXPECT_NEAR(ev.checks[0].error.y(), 0.0, 1e-9);
  EXPECT_NEAR(ev.checks[2].error.y(), 4 * kSigmaYM, 1e-9);
  EXPECT_NEAR(*ev.max_error_m, 4 * kSigmaYM, 1e-9);
  EXPECT_NEAR(*ev.rms_error_m,
              std::sqrt((std::pow(6 * kSigmaXM, 2) + std::pow(4 * kSigmaYM, 2)) / 3.0), 1e-9);
  EXPECT_NEAR(*ev.max_mahalanobis, 6.0, 1e-6);
  // The threshold is the config's: at 7 sigma none of them is false.
  EXPECT_EQ(check_closures(closures, circle_truth(20), {}, 7.0).false_closures, 0u);
}

TEST(LoopClosures, CorrelatedCovarianceIsUsedWhole) {
  // Errors along a strongly correlated x-y direction are cheap; across it they are expensive.
  LoopClosure along = closure(1, 2, 2'000'000, 9'000'000, Pose2(0.03, 0.03, 0.0));
  LoopClosure across = closure(3, 4, 2'000'000, 9'000'000, Pose2(0.03, -0.03, 0.0));
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  C << 1e-4, 0.99e-4, 0, 0.99e-4, 1e-4, 0, 0, 0, 1e-6;
  along.covariance = across.covariance = C;
  const ClosureEvaluation ev = check_closures({along, across}, circle_truth(10), {}, kFive);
  ASSERT_EQ(ev.checks.size(), 2u);
  // e^T C^-1 e: along (1,1)/sqrt2 the variance is 1.99e-4, across 0.01e-4.
  EXPECT_NEAR(*ev.checks[0].mahalanobis, std::sqrt(2 * 0.03 * 0.03 / 1.99e-4), 1e-6);
  EXPECT_NEAR(*ev.checks[1].mahalanobis, std::sqrt(2 * 0.03 * 0.03 / 0.01e-4), 1e-6);
  EXPECT_FALSE(ev.checks[0].is_false);
  EXPECT_TRUE(ev.checks[1].is_false);
}

TEST(LoopClosures, TimesOutsideTheReferenceAreUnmatched) {
  const std::vector<LoopClosure> closures = {
      closure(0, 9, 500'000, 5'000'000),      // from before the reference starts
      closure(1, 10, 2'000'000, 40'000'000),  // to after it ends
      closure(2, 11, 2'000'000, 6'000'000),   // fine
  };
  const ClosureEvaluation ev = check_closures(closures, circle_truth(10), {}, kFive);
  EXPECT_EQ(ev.closures, 3u);
  EXPECT_EQ(ev.unmatched, 2u);
  EXPECT_EQ(ev.false_closures, 0u);
  EXPECT_FALSE(ev.checks[0].matched);
  EXPECT_TRUE(ev.checks[2].matched);
  // Nothing matched: figures are absent, not zero.
  const ClosureEvaluation none = check_closures({closures[0]}, circle_truth(10), {}, kFive);
  EXPECT_FALSE(none.max_mahalanobis || none.max_error_m || none.rms_error_m);
}

TEST(LoopClosures, CovarianceThatIsNotPositiveDefiniteIsReported) {
  LoopClosure c = closure(1, 2, 2'000'000, 6'000'000, Pose2(1.0, 0.0, 0.0));
  c.covariance.setZero();
  const ClosureEvaluation ev = check_closures({c}, circle_truth(10), {}, kFive);
  EXPECT_EQ(ev.bad_covariance, 1u);
  EXPECT_EQ(ev.false_closures, 0u);
  EXPECT_FALSE(ev.checks[0].mahalanobis);
  EXPECT_NEAR(*ev.max_error_m, 1.0, 1e-9);
}

// A frontend that slips once, at 10 s, by 0.3 m and 0.05 rad: its relative pose across the slip
// is wrong, but within 2 s of any time away from it it moves as the truth does.
Trajectory slipping_frontend() {
  return test::sample(
      [](double t_s) {
        const Pose2 slip = t_s < 10.0 ? Pose2() : Pose2(0.3, -0.1, 0.05);
        return slip * circle_pose(t_s);
      },
      1'000'000, 100'000, 191);  // 10 Hz, 1-20 s
}

// The truth between scans at `t1_us` and `t2_us`, as a relations file would hold it.
Relation relation(int64_t t1_us, int64_t t2_us) {
  Relation r;
  r.t1_utime = t1_us;
  r.t2_utime = t2_us;
  r.T_1_2 = between(circle_pose(1e-6 * static_cast<double>(t1_us)),
                    circle_pose(1e-6 * static_cast<double>(t2_us)));
  return r;
}

TEST(LoopClosuresByRelations, TheTruthIsBridgedByTheFrontendOnlyNearTheKeyPoses) {
  // Key poses at 3 s and 16 s; the relation's scans 0.6 s and 1.2 s from them: the frontend's
  // slip between them (0.3 m) stays out of the truth.
  const std::vector<Relation> relations = {relation(3'600'000, 14'800'000)};
  const std::vector<LoopClosure> closures = {
      closure(1, 40, 3'000'000, 16'000'000),                                // exact
      closure(2, 41, 3'000'000, 16'000'000, Pose2(6 * kSigmaXM, 0.0, 0.0)),  // 6 sigmas off
  };
  const ClosureEvaluation ev =
      check_closures_by_relations(closures, slipping_frontend(), relations, 2'000'000, kFive);
  ASSERT_EQ(ev.checks.size(), 2u);
  EXPECT_EQ(ev.unmatched, 0u);
  EXPECT_NEAR(ev.checks[0].mahalanobis.value(), 0.0, 1e-6);
  EXPECT_FALSE(ev.checks[0].is_false);
  EXPECT_NEAR(ev.checks[1].mahalanobis.value(), 6.0, 1e-6);
  EXPECT_TRUE(ev.checks[1].is_false);
  EXPECT_EQ(ev.false_closures, 1u);
  // The frontend's own relative pose between the key poses carries the slip: a closure equal to
  // it is false by the relation.
  LoopClosure like_frontend = closures[0];
  const Trajectory f = slipping_frontend();
  like_frontend.T_from_to = between(f[20].pose, f[150].pose);  // 3 s and 16 s
  const ClosureEvaluation slipped =
      check_closures_by_relations({like_frontend}, f, relations, 2'000'000, kFive);
  EXPECT_TRUE(slipped.checks[0].is_false);
}

TEST(LoopClosuresByRelations, ARelationIsUsedEitherWayRoundAndTheNearestWins) {
  const std::vector<Relation> relations = {
      relation(15'000'000, 4'500'000),  // reversed: its t2 near the older key pose; 2.5 s away
      relation(15'500'000, 3'200'000),  // reversed, 0.7 s away in all: the one used
  };
  ClosureEvaluation ev = check_closures_by_relations({closure(1, 40, 3'000'000, 16'000'000)},
                                                     slipping_frontend(), relations, 2'000'000,
                                                     kFive);
  ASSERT_EQ(ev.checks.size(), 1u);
  ASSERT_TRUE(ev.checks[0].matched);
  EXPECT_NEAR(*ev.max_error_m, 0.0, 1e-9);
  // A relation that is itself wrong moves the truth: the wrong one is not used when a nearer one
  // exists, and is used when it is the only one in the window.
  std::vector<Relation> with_wrong = relations;
  with_wrong.push_back(relation(3'900'000, 15'900'000));
  with_wrong.back().T_1_2 = with_wrong.back().T_1_2 * Pose2(0.2, 0.0, 0.0);  // 0.9 + 0.1 s away
  ev = check_closures_by_relations({closure(1, 40, 3'000'000, 16'000'000)}, slipping_frontend(),
                                   with_wrong, 2'000'000, kFive);
  EXPECT_NEAR(*ev.max_error_m, 0.0, 1e-9);
  ev = check_closures_by_relations({closure(1, 40, 3'000'000, 16'000'000)}, slipping_frontend(),
                                   {with_wrong.back()}, 2'000'000, kFive);
  EXPECT_NEAR(*ev.max_error_m, 0.2, 1e-9);
}

TEST(LoopClosuresByRelations, MediansSetTheClosuresBesideTheFrontendsOwnRelativePose) {
  const std::vector<Relation> relations = {relation(3'600'000, 14'800'000)};
  const std::vector<LoopClosure> closures = {
      closure(1, 40, 3'000'000, 16'000'000),                          // exact
      closure(2, 41, 3'000'000, 16'000'000, Pose2(0.0, 0.06, 0.01)),  // 3 and 2 sigmas
      closure(3, 42, 3'000'000, 6'000'000),                           // no relation near
  };
  const Trajectory f = slipping_frontend();
  const ClosureEvaluation ev =
      check_closures_by_relations(closures, f, relations, 2'000'000, kFive);
  // The frontend's own relative pose across its slip, against the same truth: the same for both
  // checked closures, none for the unchecked one.
  const Pose2 E = between(between(f[20].pose, f[150].pose), ev.checks[0].T_true);  // 3 s, 16 s
  const Eigen::Vector3d slip_error(E.x(), E.y(), wrap_angle(E.theta()));
  ASSERT_TRUE(ev.checks[0].frontend_error && ev.checks[1].frontend_error);
  EXPECT_TRUE(ev.checks[0].frontend_error->isApprox(slip_error, 1e-9));
  EXPECT_FALSE(ev.checks[2].frontend_error);
  EXPECT_GT(slip_error.head<2>().norm(), 0.1);
  const ClosureMedians m = medians(ev);
  EXPECT_EQ(m.checked, 2u);
  // Two values: the median is the mean of the two.
  EXPECT_NEAR(m.error_m.value(), 0.03, 1e-9);
  EXPECT_NEAR(m.error_rad.value(), 0.005, 1e-9);
  EXPECT_NEAR(m.max_error_rad.value(), 0.01, 1e-9);
  EXPECT_NEAR(m.mahalanobis.value(), 0.5 * std::hypot(3.0, 2.0), 1e-6);
  EXPECT_NEAR(m.frontend_error_m.value(), slip_error.head<2>().norm(), 1e-9);
  EXPECT_NEAR(m.frontend_error_rad.value(), std::abs(slip_error.z()), 1e-9);
  EXPECT_EQ(m.closure_nearer, 2u);  // both nearer the truth than the slipped frontend
  // Three values: the middle one.
  std::vector<LoopClosure> three = closures;
  three[2] = closure(4, 43, 3'000'000, 16'000'000, Pose2(0.0, 0.02, 0.0));
  EXPECT_NEAR(
      medians(check_closures_by_relations(three, f, relations, 2'000'000, kFive)).error_m.value(),
      0.02, 1e-9);
  // Nothing checked: no figure, not zero.
  const ClosureMedians none =
      medians(check_closures_by_relations({closures[2]}, f, relations, 2'000'000, kFive));
  EXPECT_EQ(none.checked, 0u);
  EXPECT_FALSE(none.error_m || none.mahalanobis || none.frontend_error_m);
}

TEST(LoopClosuresByRelations, AClosureNoRelationReachesIsUnmatched) {
  const std::vector<Relation> relations = {relation(3'000'000, 12'000'000)};  // 4 s from `to`
  const ClosureEvaluation ev = check_closures_by_relations(
      {closure(1, 40, 3'000'000, 16'000'000)}, slipping_frontend(), relations, 2'000'000, kFive);
  EXPECT_EQ(ev.unmatched, 1u);
  EXPECT_FALSE(ev.checks[0].matched);
  EXPECT_FALSE(ev.max_error_m);
  const ClosureEvaluation no_frontend =
      check_closures_by_relations({closure(1, 40, 3'000'000, 12'000'000)}, {}, relations,
                                  2'000'000, kFive);
  EXPECT_EQ(no_frontend.unmatched, 1u);
}

TEST(LoopClosuresByRelations, TheFrontendsErrorOverShortSpansWidensTheTruthsCovariance) {
  // A frontend whose heading alternates +-0.01 rad about the truth from sample to sample: over
  // 0.1 s it errs by 0.02 rad, which 30 relations between neighbouring samples measure.
  const Trajectory wobbling = test::sample(
      [](double t_s) {
        const int i = static_cast<int>(std::lround((t_s - 1.0) * 10.0));
        return circle_pose(t_s) * Pose2(0.0, 0.0, i % 2 == 0 ? 0.01 : -0.01);
      },
      1'000'000, 100'000, 191);
  std::vector<Relation> relations;
  for (int i = 0; i < 30; ++i) {
    relations.push_back(relation(1'000'000 + i * 100'000, 1'100'000 + i * 100'000));
  }
  // The closure's from-end on the relation's scan (no bridge); its to-end 1.2 s (12 samples, the
  // same sign) after the relation's other scan: one bridge, exact here, of variance 0.02^2 rad^2.
  relations.push_back(relation(3'000'000, 14'800'000));
  const LoopClosure c = closure(1, 40, 3'000'000, 16'000'000, Pose2(0.0, 0.0, 6 * kSigmaThetaRad));
  const ClosureEvaluation ev =
      check_closures_by_relations({c}, wobbling, relations, 2'000'000, kFive);
  ASSERT_TRUE(ev.checks[0].matched);
  EXPECT_NEAR(ev.checks[0].error.z(), 6 * kSigmaThetaRad, 1e-9);
  const double expected = 6 * kSigmaThetaRad / std::hypot(kSigmaThetaRad, 0.02);
  // (The bridge turns its translation by the wobble, 5 mm against sigmas of 1-2 cm: 3 %.)
  EXPECT_NEAR(ev.checks[0].mahalanobis.value(), expected, 0.03 * expected);
  EXPECT_FALSE(ev.checks[0].is_false);
  EXPECT_NEAR(ev.bridge_covariance(2, 2), 0.02 * 0.02, 1e-12);
  // Without the short relations the same closure is six sigmas off.
  relations.erase(relations.begin(), relations.begin() + 30);
  const ClosureEvaluation alone =
      check_closures_by_relations({c}, wobbling, relations, 2'000'000, kFive);
  EXPECT_NEAR(alone.checks[0].mahalanobis.value(), 6.0, 0.01);
  EXPECT_TRUE(alone.bridge_covariance.isZero());
  EXPECT_TRUE(alone.checks[0].is_false);
}

TEST(LoopClosureSet, RepeatedClosureIsKeptOnce) {
  LoopClosureSet set;
  set.add(closure(1, 2, 2'000'000, 6'000'000, Pose2(1.0, 0.0, 0.0)));
  set.add(closure(1, 3, 2'000'000, 7'000'000));
  set.add(closure(1, 2, 2'000'000, 6'000'000));  // the same pair again: replaces the first
  EXPECT_EQ(set.size(), 2u);
  EXPECT_EQ(set.repeated(), 1u);
  const ClosureEvaluation ev = check_closures(set.closures(), circle_truth(10), {}, kFive);
  EXPECT_NEAR(*ev.max_error_m, 0.0, 1e-9);
}

}  // namespace
}  // namespace traverse::evaluator
