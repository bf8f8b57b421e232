// The motion prior (motion_prior.hpp): odometry interpolated to a time, extrapolated a little,
// refused or given up on where it is out of order, missing, gapped or stale; the combination with
// the IMU in the motion model; the search windows sized by the step's covariance.
#include "motion_prior.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "hector/motion_model.hpp"

namespace traverse::frontend {
namespace {

// Odometry of a base driving 1 m/s forward, turning 0.2 rad/s, in a frame anywhere, every 20 ms
// from t0 to t1 [us].
OdometrySample sample_at(int64_t t) {
  OdometrySample o;
  o.utime = t;
  const double s = 1e-6 * static_cast<double>(t);
  o.T_odom_base = Pose2(30.0, -4.0, 1.0) * Pose2::exp(Eigen::Vector3d(1.0, 0.0, 0.2) * s);
  return o;
}
void feed(MotionPrior& prior, int64_t t0, int64_t t1, int64_t step = 20'000) {
  for (int64_t t = t0; t <= t1; t += step) ASSERT_TRUE(prior.add_odometry(sample_at(t)));
}
Pose2 truth_step(int64_t t0, int64_t t1) {
  return between(sample_at(t0).T_odom_base, sample_at(t1).T_odom_base);
}

TEST(MotionPrior, InterpolatesToTimesBetweenSamples) {
  MotionPrior prior(MotionPriorConfig{});
  feed(prior, 0, 2'000'000);
  OdometryMiss miss = OdometryMiss::kMissing;
  // 0.311 s and 1.777 s lie between samples; the samples lie on one arc, so geodesic
  // interpolation is exact.
  const auto step = prior.odometry_step(311'000, 1'777'000, &miss);
  ASSERT_TRUE(step);
  EXPECT_EQ(miss, OdometryMiss::kNone);
  EXPECT_FALSE(step->extrapolated);
  const Pose2 expected = truth_step(311'000, 1'777'000);
  EXPECT_LT((step->T_base0_base1.translation() - expected.translation()).norm(), 1e-9);
  EXPECT_NEAR(step->T_base0_base1.theta(), expected.theta(), 1e-9);
  // No covariance in the messages: the model's, growing with the distance (1.466 m) and turn.
  const double sxy = 0.02 + 0.1 * expected.translation().norm();
  EXPECT_NEAR(step->covariance(0, 0), sxy * sxy, 1e-9);
  EXPECT_GT(step->covariance(2, 2), std::pow(0.01 + 0.05 * 1.4, 2));
}

TEST(MotionPrior, ExtrapolatesALittleThenFallsBackAsStale) {
  MotionPriorConfig config;
  config.odometry_max_extrapolation_us = 200'000;
  MotionPrior prior(config);
  feed(prior, 0, 1'000'000);
  // 0.1 s past the newest sample: the newest rate carried on (exact here), its sigmas doubled.
  const auto late = prior.odometry_step(500'000, 1'100'000);
  ASSERT_TRUE(late);
  EXPECT_TRUE(late->extrapolated);
  EXPECT_LT(
      (late->T_base0_base1.translation() - truth_step(500'000, 1'100'000).translation()).norm(),
      1e-9);
  const auto inside = prior.odometry_step(500'000, 1'000'000);
  EXPECT_GT(late->covariance(0, 0), 3.9 * inside->covariance(0, 0));
  // 0.3 s past: the odometry stopped or lags too much.
  OdometryMiss miss = OdometryMiss::kNone;
  EXPECT_FALSE(prior.odometry_step(500'000, 1'300'000, &miss));
  EXPECT_EQ(miss, OdometryMiss::kStale);
}

// A logger that stamps samples on arrival bunches them (intel: several a millisecond apart, then
// nothing for half a second). Carried past the newest sample, the rate is measured over at least
// the time it is carried: the last increment alone (1 ms) carried 90 ms on would be 90 of them.
TEST(MotionPrior, ExtrapolatesAtTheRateOverAsLongAsItCarriesIt) {
  MotionPrior prior(MotionPriorConfig{});
  feed(prior, 0, 200'000);  // on time, every 20 ms, to 0.2 s
  // The samples of 0.22, 0.24 and 0.26 s arrive, and are stamped, at 0.500, 0.501 and 0.502 s.
  for (int i = 0; i < 3; ++i) {
    OdometrySample o = sample_at(220'000 + 20'000 * i);
    o.utime = 500'000 + 1'000 * i;
    ASSERT_TRUE(prior.add_odometry(o));
  }
  const auto step = prior.odometry_step(200'000, 592'000);
  ASSERT_TRUE(step);
  EXPECT_TRUE(step->extrapolated);
  // From 0.2 s the base went 0.06 m by the samples, then at their rate over the 0.302 s since
  // 0.2 s (0.2 m/s) for the 0.09 s past the newest: 0.078 m. One millisecond's increment (0.02 m)
  // carried 90 ms on would make it 1.86 m.
  EXPECT_NEAR(step->T_base0_base1.translation().norm(), 0.06 + 0.06 * 90.0 / 302.0, 0.005);
}

TEST(MotionPrior, MissingGappedAndOutOfOrderOdometry) {
  MotionPriorConfig config;
  config.odometry_max_gap_us = 500'000;
  MotionPrior prior(config);
  OdometryMiss miss = OdometryMiss::kNone;
  EXPECT_FALSE(prior.odometry_step(0, 100'000, &miss));  // nothing yet
  EXPECT_EQ(miss, OdometryMiss::kMissing);
  feed(prior, 1'000'000, 2'000'000);
  EXPECT_FALSE(prior.odometry_step(900'000, 1'500'000, &miss));  // starts before the first
  EXPECT_EQ(miss, OdometryMiss::kMissing);
  // Refused: not after the newest, or not finite; nothing kept.
  EXPECT_FALSE(prior.add_odometry(sample_at(2'000'000)));
  EXPECT_FALSE(prior.add_odometry(sample_at(1'500'000)));
  OdometrySample nan = sample_at(2'100'000);
  nan.T_odom_base = Pose2(std::nan(""), 0.0, 0.0);
  EXPECT_FALSE(prior.add_odometry(nan));
  // A second without samples (the odometry stopped, then came back): not interpolated across.
  feed(prior, 3'000'000, 3'500'000);
  EXPECT_FALSE(prior.odometry_step(1'500'000, 2'500'000, &miss));
  EXPECT_EQ(miss, OdometryMiss::kGap);
  EXPECT_TRUE(prior.odometry_step(3'100'000, 3'400'000, &miss));
  EXPECT_EQ(miss, OdometryMiss::kNone);
}

TEST(MotionPrior, SourceSelectsWhatIsUsed) {
  for (const char* source : {"imu", "none"}) {
    MotionPriorConfig config;
    config.source = source;
    MotionPrior prior(config);
    feed(prior, 0, 1'000'000);
    EXPECT_FALSE(prior.odometry_step(100'000, 900'000)) << source;
    EXPECT_FALSE(prior.uses_odometry());
  }
  MotionPriorConfig config;
  config.source = "odometry";
  EXPECT_FALSE(MotionPrior(config).uses_imu());
  EXPECT_TRUE(MotionPrior(config).uses_odometry());
}

// Source both: odometry's translation, the IMU's rotation (the wheels say 0.2 rad/s, the gyro
// 0.5 rad/s); source odometry: both from odometry.
TEST(MotionPrior, BothTakesTranslationFromOdometryAndRotationFromTheImu) {
  for (const char* source : {"both", "odometry"}) {
    MotionPriorConfig config;
    config.source = source;
    MotionModel motion(Pose2(), Eigen::Matrix3d::Identity(), config);
    motion.add_pose(0, Pose2(), Eigen::Matrix3d::Identity() * 1e-4, false);
    for (int64_t t = 0; t <= 1'000'000; t += 20'000) {
      ASSERT_TRUE(motion.add_odometry(sample_at(t)));
      ASSERT_TRUE(motion.add_imu(t, Eigen::Vector3d(0.0, 0.0, 0.5)));
    }
    const bool use_imu = motion.imu_covers(0, 600'000);
    EXPECT_EQ(use_imu, std::string(source) == "both");
    const MotionModel::Prediction p = motion.predict(600'000, use_imu, false);
    ASSERT_TRUE(p.odometry);
    const Pose2 odo = truth_step(0, 600'000);
    EXPECT_LT((p.T_map_base.translation() - odo.translation()).norm(), 1e-9);
    EXPECT_NEAR(p.T_map_base.theta(), use_imu ? 0.3 : odo.theta(), 1e-6) << source;
  }
}

TEST(MotionPrior, SearchWindowsFollowTheCovariance) {
  MotionPrior prior(MotionPriorConfig{});  // 3 sigmas, at least 0.3 m and 0.15 rad
  const Eigen::Matrix3d c = Eigen::Vector3d(0.04, 0.01, 0.01).asDiagonal();
  EXPECT_NEAR(prior.linear_window_m(c, 2.0), 0.6, 1e-12);
  EXPECT_NEAR(prior.angular_window_rad(c, 2.5), 0.3, 1e-12);
  EXPECT_NEAR(prior.linear_window_m(c, 0.5), 0.5, 1e-12);  // at most the matcher's
  EXPECT_NEAR(prior.linear_window_m(Eigen::Matrix3d::Zero(), 2.0), 0.3, 1e-12);
  EXPECT_NEAR(prior.angular_window_rad(Eigen::Matrix3d::Zero(), 2.5), 0.15, 1e-12);
}

}  // namespace
}  // namespace traverse::frontend
