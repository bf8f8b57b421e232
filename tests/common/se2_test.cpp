#include "se2.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace traverse {
namespace {

void expect_near(const Pose2& a, const Pose2& b, double tol) {
  EXPECT_NEAR(a.x(), b.x(), tol);
  EXPECT_NEAR(a.y(), b.y(), tol);
  EXPECT_NEAR(wrap_angle(a.theta() - b.theta()), 0.0, tol);
}

Pose2 random_pose(std::mt19937& rng, double max_angle = M_PI) {
  std::uniform_real_distribution<double> u(-5.0, 5.0), a(-max_angle, max_angle);
  return Pose2(u(rng), u(rng), a(rng));
}

TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(wrap_angle(M_PI), M_PI);
  EXPECT_DOUBLE_EQ(wrap_angle(-M_PI), M_PI);
  EXPECT_NEAR(wrap_angle(3 * M_PI + 0.1), -M_PI + 0.1, 1e-12);
  EXPECT_NEAR(wrap_angle(-7.0), -7.0 + 2 * M_PI, 1e-12);
  EXPECT_NEAR(wrap_angle(1e-300), 1e-300, 0.0);
}

TEST(Pose2, ComposeAndInverse) {
  const Pose2 a(1.0, 2.0, M_PI / 2);
  const Pose2 b(1.0, 0.0, 0.0);
  expect_near(a * b, Pose2(1.0, 3.0, M_PI / 2), 1e-12);
  expect_near(a * a.inverse(), Pose2(), 1e-12);
  const Eigen::Vector2d p = a * Eigen::Vector2d(0.0, 1.0);
  EXPECT_NEAR(p.x(), 0.0, 1e-12);
  EXPECT_NEAR(p.y(), 2.0, 1e-12);
}

TEST(Pose2, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  for (int i = 0; i < 1000; ++i) {
    const Pose2 t = random_pose(rng, 3.1);
    expect_near(Pose2::exp(t.log()), t, 1e-10);
  }
}

TEST(Pose2, ExpLogNearZeroAngle) {
  for (double th : {0.0, 1e-12, -1e-9, 1e-6, -4e-6, 1e-5, 2e-5}) {
    const Eigen::Vector3d xi(0.3, -0.2, th);
    const Eigen::Vector3d back = Pose2::exp(xi).log();
    EXPECT_NEAR((back - xi).norm(), 0.0, 1e-13) << "theta " << th;
    // A pure translation tangent maps to the same translation.
    const Pose2 t = Pose2::exp(xi);
    EXPECT_NEAR(t.x(), 0.3 - 0.5 * th * -0.2, 1e-9);
  }
}

TEST(Pose2, ExpOfQuarterTurnArc) {
  // Driving a quarter circle of radius 1: tangent (pi/2, 0, pi/2) ends at (1, 1) facing +y.
  expect_near(Pose2::exp({M_PI / 2, 0.0, M_PI / 2}), Pose2(1.0, 1.0, M_PI / 2), 1e-12);
}

TEST(Pose2, AdjointMatchesDefinition) {
  std::mt19937 rng(2);
  for (int i = 0; i < 100; ++i) {
    const Pose2 t = random_pose(rng);
    const Eigen::Vector3d xi(1e-4, -2e-4, 3e-4);
    const Eigen::Vector3d lhs = (t * Pose2::exp(xi) * t.inverse()).log();
    EXPECT_NEAR((lhs - t.adjoint() * xi).norm(), 0.0, 1e-9);
  }
}

TEST(Interpolate, EndsAndMidpoint) {
  const Pose2 a(0.0, 0.0, 0.0), b(2.0, 0.0, 0.0);
  expect_near(interpolate(a, b, 0.0), a, 1e-12);
  expect_near(interpolate(a, b, 1.0), b, 1e-12);
  expect_near(interpolate(a, b, 0.5), Pose2(1.0, 0.0, 0.0), 1e-12);
  // Across the +-pi seam the heading takes the short way.
  const Pose2 c(0, 0, 3.1), d(0, 0, -3.1);
  EXPECT_NEAR(std::abs(interpolate(c, d, 0.5).theta()), M_PI, 1e-12);
}

// Numerical Jacobian of f at pose p on the (x, y, theta) parameterisation.
template <class F>
Eigen::Matrix3d numeric_jacobian(F f, const Pose2& p) {
  Eigen::Matrix3d j;
  const double h = 1e-6;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d dp = Eigen::Vector3d::Zero();
    dp[k] = h;
    const Eigen::Vector3d plus = p.vector() + dp, minus = p.vector() - dp;
    Eigen::Vector3d d = f(Pose2(plus.x(), plus.y(), plus.z())).vector() -
                        f(Pose2(minus.x(), minus.y(), minus.z())).vector();
    d.z() = wrap_angle(d.z());
    j.col(k) = d / (2 * h);
  }
  return j;
}

TEST(Jacobians, MatchNumerical) {
  std::mt19937 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Pose2 a = random_pose(rng), b = random_pose(rng);
    const double tol = 1e-6;
    EXPECT_TRUE(compose_jacobian_a(a, b).isApprox(
        numeric_jacobian([&](const Pose2& x) { return x * b; }, a), tol));
    EXPECT_LT((compose_jacobian_b(a, b) -
               numeric_jacobian([&](const Pose2& x) { return a * x; }, b)).norm(), tol);
    EXPECT_LT((between_jacobian_a(a, b) -
               numeric_jacobian([&](const Pose2& x) { return between(x, b); }, a)).norm(), tol);
    EXPECT_LT((between_jacobian_b(a, b) -
               numeric_jacobian([&](const Pose2& x) { return between(a, x); }, b)).norm(), tol);
  }
}

TEST(Jacobians, NearZeroAngle) {
  const Pose2 a(0.5, -0.5, 1e-9), b(1.0, 2.0, -1e-9);
  EXPECT_LT((between_jacobian_a(a, b) -
             numeric_jacobian([&](const Pose2& x) { return between(x, b); }, a)).norm(), 1e-6);
}

}  // namespace
}  // namespace traverse
