// The odometry chain: the log's own increments, re-anchoring lines ignored, a covariance that
// grows with distance and turn and not with the sampling rate.
#include "odometry.hpp"

#include <gtest/gtest.h>

#include <random>

namespace traverse::carmen {
namespace {

void expect_near(const Pose2& a, const Pose2& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol);
  EXPECT_NEAR(a.y(), b.y(), tol);
  EXPECT_NEAR(wrap_angle(a.theta() - b.theta()), 0.0, tol);
}

TEST(OdometryChain, ReproducesARawLogsOdometry) {
  OdometryChain chain{OdometryNoise{}};
  EXPECT_FALSE(chain.started());
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> step(-0.05, 0.1), turn(-0.1, 0.1);
  Pose2 raw(1.0, -2.0, 0.3);
  for (int i = 0; i < 2000; ++i) {
    chain.add(raw);
    expect_near(chain.T_odom_base(), raw, 1e-9);
    raw = raw * Pose2(step(rng), 0.1 * step(rng), turn(rng));
  }
  EXPECT_GT(chain.travel_m(), 10.0);
}

// A corrected log restarts its ODOM lines at each scan's corrected pose: the chain must follow
// the raw increments, never the corrections (which would hand over the reference trajectory).
TEST(OdometryChain, ReanchoringIsNotMotion) {
  std::mt19937 rng(2);
  std::normal_distribution<double> correction(0.0, 0.05);
  OdometryChain chain{OdometryNoise{}}, plain{OdometryNoise{}};
  Pose2 raw, anchor;   // anchor: the corrected pose the log restarts from
  Pose2 since_anchor;  // raw motion since the last anchor
  const Pose2 each(0.05, 0.0, 0.02);
  for (int scan = 0; scan < 50; ++scan) {
    for (int k = 0; k < 10; ++k) {
      raw = raw * each;
      since_anchor = since_anchor * each;
      chain.add(anchor * since_anchor);  // the log's ODOM line
      plain.add(raw);
    }
    // The scan: the log restarts at a corrected pose near the one odometry gives.
    anchor = anchor * since_anchor * Pose2(correction(rng), correction(rng), correction(rng));
    since_anchor = Pose2();
    chain.reanchor(anchor);
  }
  expect_near(chain.T_odom_base(), plain.T_odom_base(), 1e-9);
}

TEST(OdometryChain, CovarianceGrowsWithDistanceNotWithSampling) {
  OdometryNoise noise;
  OdometryChain coarse(noise), fine(noise);
  coarse.add(Pose2());
  fine.add(Pose2());
  // 10 m straight ahead, in 1 step or 1000.
  coarse.add(Pose2(10.0, 0.0, 0.0));
  for (int i = 1; i <= 1000; ++i) fine.add(Pose2(0.01 * i, 0.0, 0.0));
  const double fwd = noise.forward_m_per_sqrt_m;
  EXPECT_NEAR(coarse.covariance()(0, 0), fwd * fwd * 10.0, 1e-12);
  EXPECT_NEAR(fine.covariance()(0, 0), fwd * fwd * 10.0, 1e-9);
  const double h = noise.heading_rad_per_sqrt_m;
  EXPECT_NEAR(fine.covariance()(2, 2), h * h * 10.0, 1e-9);
  // Heading error swings the position sideways: far more lateral variance when finely sampled
  // (the first-order propagation of the same random walk), never less than the lateral term.
  EXPECT_GT(fine.covariance()(1, 1), noise.lateral_m_per_sqrt_m * noise.lateral_m_per_sqrt_m * 10);
  // Turning on the spot: heading variance per angle, no translation variance.
  OdometryChain spin(noise);
  spin.add(Pose2());
  for (int i = 1; i <= 100; ++i) spin.add(Pose2(0.0, 0.0, 0.01 * i));
  const double r = noise.heading_rad_per_sqrt_rad;
  EXPECT_NEAR(spin.covariance()(2, 2), r * r * 1.0, 1e-9);
  EXPECT_NEAR(spin.covariance()(0, 0), 0.0, 1e-15);
  EXPECT_DOUBLE_EQ(spin.travel_m(), 0.0);
}

TEST(OdometryNoise, ValidateNamesTheKey) {
  OdometryNoise n;
  EXPECT_FALSE(validate(n));
  n.lateral_m_per_sqrt_m = -0.1;
  EXPECT_NE(validate(n)->find("lateral_m_per_sqrt_m"), std::string::npos);
  n = OdometryNoise{};
  n.velocity_turn_radps = 0.0;
  EXPECT_NE(validate(n)->find("velocity_turn_radps"), std::string::npos);
}

}  // namespace
}  // namespace traverse::carmen
