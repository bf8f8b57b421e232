#include "extrinsic_yaw.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cart_path.hpp"

namespace traverse::calibration {
namespace {

using test::as_tracked;
using test::cart_path;

// The yaw of a scanner turned by 0.3 or -0.1 deg on the cart comes back to 0.06 deg from 84 m of
// path with 2 mm of noise on every pose (a chord's angle 3 mrad), also when the tracked point lies
// 0.3 m ahead of the axle (its sideways slip on the weave must not bias the yaw; the corners
// turn too much within a chord to be taken). The stated standard deviation covers the error.
TEST(ExtrinsicYaw, RecoversTheScannersYawFromTheCartsPath) {
  for (const double lever : {0.0, 0.3}) {
    for (const double delta : {0.00524, -0.00175}) {
      ExtrinsicYawEstimator estimator{ExtrinsicYawConfig{}};
      for (const Pose2& T : as_tracked(cart_path(0.01, lever), delta, 0.002, 7)) {
        estimator.add_pose(T);
      }
      ASSERT_TRUE(estimator.yaw_rad().has_value());
      EXPECT_NEAR(*estimator.yaw_rad(), delta, 1e-3) << "lever " << lever;
      EXPECT_GT(estimator.travel_m(), 70.0);
      EXPECT_LT(estimator.yaw_sigma_rad(), 1e-3);
      EXPECT_LT(std::abs(*estimator.yaw_rad() - delta), 3.0 * estimator.yaw_sigma_rad());
    }
  }
}

// Key poses a third of a metre apart (the backend's) give the same yaw as the frontend's
// centimetre steps; reset() forgets everything, so a re-estimated trajectory is fitted afresh.
TEST(ExtrinsicYaw, KeyPoseSpacingAndReset) {
  ExtrinsicYawEstimator estimator{ExtrinsicYawConfig{}};
  for (const Pose2& T : as_tracked(cart_path(0.33, 0.0), 0.004, 0.001, 3)) estimator.add_pose(T);
  ASSERT_TRUE(estimator.yaw_rad().has_value());
  EXPECT_NEAR(*estimator.yaw_rad(), 0.004, 5e-4);
  estimator.reset();
  EXPECT_EQ(estimator.chords(), 0);
  EXPECT_FALSE(estimator.yaw_rad().has_value());
  for (const Pose2& T : as_tracked(cart_path(0.33, 0.0), -0.002, 0.001, 4)) estimator.add_pose(T);
  ASSERT_TRUE(estimator.yaw_rad().has_value());
  EXPECT_NEAR(*estimator.yaw_rad(), -0.002, 5e-4);
}

// A noisier path gives a wider standard deviation, taken from the chords' scatter: 2 cm of noise
// on each pose where 5 mm are assumed.
TEST(ExtrinsicYaw, StandardDeviationGrowsWithTheScatter) {
  ExtrinsicYawEstimator quiet{ExtrinsicYawConfig{}}, noisy{ExtrinsicYawConfig{}};
  for (const Pose2& T : as_tracked(cart_path(0.33, 0.0), 0.003, 0.001, 5)) quiet.add_pose(T);
  for (const Pose2& T : as_tracked(cart_path(0.33, 0.0), 0.003, 0.02, 5)) noisy.add_pose(T);
  ASSERT_TRUE(quiet.yaw_rad() && noisy.yaw_rad());
  EXPECT_GT(noisy.yaw_sigma_rad(), 2.0 * quiet.yaw_sigma_rad());
  EXPECT_LT(std::abs(*noisy.yaw_rad() - 0.003), 3.0 * noisy.yaw_sigma_rad());
}

// Until min_travel_m of chords went in, no estimate is given; turning on the spot adds none.
TEST(ExtrinsicYaw, NoEstimateBeforeEnoughTravel) {
  ExtrinsicYawEstimator estimator{ExtrinsicYawConfig{}};
  Pose2 T;
  for (int k = 0; k < 200; ++k) {  // a turn on the spot
    T = T * Pose2(0.0, 0.0, 0.02);
    estimator.add_pose(T);
  }
  EXPECT_EQ(estimator.chords(), 0);
  const auto tracked = as_tracked(cart_path(0.01, 0.0), 0.003, 0.0, 1);
  for (std::size_t k = 0; k < 900; ++k) estimator.add_pose(tracked[k]);
  EXPECT_LT(estimator.travel_m(), 10.0);
  EXPECT_FALSE(estimator.yaw_rad().has_value());
}

// A yaw beyond max_yaw_rad is not applied (the rig file needs a calibration, not a correction).
TEST(ExtrinsicYaw, LargeYawIsNotApplied) {
  ExtrinsicYawEstimator estimator{ExtrinsicYawConfig{}};
  for (const Pose2& T : as_tracked(cart_path(0.01, 0.0), 0.1, 0.0, 1)) estimator.add_pose(T);
  EXPECT_GT(estimator.travel_m(), 60.0);
  EXPECT_FALSE(estimator.yaw_rad().has_value());
}

// The base's pose for a tracked one: its position turned about the origin, its heading kept.
TEST(ExtrinsicYaw, TurnedAboutTheFirstPose) {
  const Pose2 T = turned_about(Pose2(3.0, 1.0, 0.4), Eigen::Vector2d(1.0, 1.0), M_PI / 2);
  EXPECT_NEAR(T.x(), 1.0, 1e-12);
  EXPECT_NEAR(T.y(), 3.0, 1e-12);
  EXPECT_NEAR(T.theta(), 0.4, 1e-12);
}

TEST(ExtrinsicYaw, ConfigValidation) {
  ExtrinsicYawConfig c;
  EXPECT_EQ(validate(c), std::nullopt);
  c.chord_m = 0.0;
  ASSERT_TRUE(validate(c).has_value());
  EXPECT_NE(validate(c)->find("chord_m"), std::string::npos);
  c = ExtrinsicYawConfig{};
  c.max_yaw_rad = -1.0;
  ASSERT_TRUE(validate(c).has_value());
  EXPECT_NE(validate(c)->find("max_yaw_rad"), std::string::npos);
}

}  // namespace
}  // namespace traverse::calibration
