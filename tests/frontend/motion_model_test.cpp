// The motion model (hector/motion_model.hpp): what it predicts from poses, IMU and odometry.
#include "hector/motion_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace traverse::frontend {
namespace {

const Eigen::Matrix3d kCovariance = Eigen::Matrix3d::Identity() * 1e-4;

// Poses along an arc at 0.5 m/s turning at 0.2 rad/s, every 20 ms: the next pose is predicted by
// the velocity of the last ones.
TEST(MotionModel, ExtrapolatesTheVelocityOfTheLastPoses) {
  MotionModel motion(Pose2(), Eigen::Matrix3d::Identity());
  const auto truth = [](int64_t t) {
    return Pose2::exp(Eigen::Vector3d(0.5, 0.0, 0.2) * (1e-6 * static_cast<double>(t)));
  };
  for (int64_t t = 0; t <= 2'000'000; t += 20'000) motion.add_pose(t, truth(t), kCovariance, false);
  const Pose2 predicted = motion.extrapolate(2'020'000, false, false);
  EXPECT_LT((predicted.translation() - truth(2'020'000).translation()).norm(), 1e-8);
  EXPECT_LT(std::abs(wrap_angle(predicted.theta() - truth(2'020'000).theta())), 1e-8);
  // After a pause the step is bounded by twice the last interval.
  const Pose2 after_pause = motion.extrapolate(5'000'000, false, false);
  EXPECT_LT((after_pause.translation() - truth(2'040'000).translation()).norm(), 1e-8);
}

// The IMU's yaw rate gives the heading change when it covers the interval; a predicted pose
// leaves the velocity as it was.
TEST(MotionModel, HeadingFromTheImuAndNoVelocityFromAPrediction) {
  MotionModel motion(Pose2(1.0, 2.0, 0.5), Eigen::Matrix3d::Identity());
  motion.add_pose(0, Pose2(1.0, 2.0, 0.5), kCovariance, false);
  motion.add_pose(100'000, Pose2(1.05, 2.0, 0.5), kCovariance, false);
  const Eigen::Vector3d velocity = motion.velocity();
  motion.add_prediction(200'000, Pose2(3.0, 2.0, 0.5), kCovariance, false);
  EXPECT_EQ(motion.velocity(), velocity);
  EXPECT_EQ(motion.last_pose().vector(), Pose2(3.0, 2.0, 0.5).vector());
  for (int64_t t = 0; t <= 400'000; t += 5'000) motion.add_imu(t, Eigen::Vector3d(0, 0, 1.5));
  ASSERT_TRUE(motion.imu_covers(200'000, 300'000));
  EXPECT_NEAR(motion.extrapolate(300'000, true, false).theta(), 0.5 + 0.15, 1e-12);
}

// Wheel odometry covering the interval since the last pose gives the step, wherever the poses'
// velocity would have put it; its drifting frame does not matter, only its relative motion.
TEST(MotionModel, OdometryGivesTheStepWhereItCoversTheInterval) {
  MotionModel motion(Pose2(), Eigen::Matrix3d::Identity());
  motion.add_pose(0, Pose2(), kCovariance, false);
  motion.add_pose(1'000'000, Pose2(0.1, 0.0, 0.0), kCovariance, false);  // 0.1 m/s so far
  const Pose2 T_odom_start(50.0, -20.0, 2.0);  // the odometry frame is anywhere
  for (int64_t t = 900'000; t <= 3'100'000; t += 100'000) {
    OdometrySample o;
    o.utime = t;
    // 1 m/s forward, turning 0.1 rad/s, from t = 1 s on.
    const double s = 1e-6 * static_cast<double>(std::max<int64_t>(0, t - 1'000'000));
    o.T_odom_base = T_odom_start * Pose2::exp(Eigen::Vector3d(1.0, 0.0, 0.1) * s);
    ASSERT_TRUE(motion.add_odometry(o));
  }
  const Pose2 predicted = motion.extrapolate(3'000'000, false, true);
  const Pose2 expected = Pose2(0.1, 0.0, 0.0) * Pose2::exp(Eigen::Vector3d(2.0, 0.0, 0.2));
  EXPECT_LT((predicted.translation() - expected.translation()).norm(), 1e-9);
  EXPECT_NEAR(predicted.theta(), expected.theta(), 1e-9);
  // Past the odometry's last sample by more than motion_prior.odometry_max_extrapolation_us
  // (0.2 s) the poses' velocity predicts again.
  const Pose2 beyond = motion.extrapolate(3'400'000, false, false);
  EXPECT_NEAR(beyond.x(), 0.1 + 0.1 * 2.0, 1e-9);
  OdometrySample stale;
  stale.utime = 2'000'000;
  EXPECT_FALSE(motion.add_odometry(stale));
}

// A robot at 1 m/s along a corridor, 75 scans a second; one match lands 5 cm ahead along the
// axis (the walls barely hold it there). Unbounded, the velocity of the last poses takes that as
// 4 m/s over one interval and the next prediction carries on half a metre a second too fast;
// bounded at 1 m/s^2 it changes by 1.3 cm/s at most.
TEST(MotionModel, OneMatchOffAlongTheAxisIsNoChangeOfSpeed) {
  constexpr int64_t kInterval = 13'333;  // [us]
  const auto velocity_after_slip = [&](double max_acceleration_mps2) {
    MotionPriorConfig prior;
    prior.max_acceleration_mps2 = max_acceleration_mps2;
    MotionModel motion(Pose2(), Eigen::Matrix3d::Identity(), prior);
    int64_t t = 0;
    for (; t <= 2'000'000; t += kInterval)
      motion.add_pose(t, Pose2(1e-6 * static_cast<double>(t), 0.0, 0.0), kCovariance, false);
    const double before = motion.velocity().x();
    motion.add_pose(t, Pose2(1e-6 * static_cast<double>(t) + 0.05, 0.0, 0.0), kCovariance, false);
    return motion.velocity().x() - before;
  };
  EXPECT_GT(velocity_after_slip(0.0), 0.4);  // [m/s]
  EXPECT_LE(velocity_after_slip(1.0), 1.0 * 1e-6 * kInterval + 1e-9);
  EXPECT_GT(velocity_after_slip(1.0), 0.0);
}

}  // namespace
}  // namespace traverse::frontend
