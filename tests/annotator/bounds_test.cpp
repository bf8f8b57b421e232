// The 95 % radius of a 2D Gaussian error: closed-form limits, Monte Carlo, and the two other
// bounds' relation to it.
#include "bounds.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

namespace traverse::annotator {
namespace {

Eigen::Matrix2d rotated(double sigma1, double sigma2, double angle) {
  const Eigen::Matrix2d R = Eigen::Rotation2Dd(angle).toRotationMatrix();
  return R * Eigen::Vector2d(sigma1 * sigma1, sigma2 * sigma2).asDiagonal() * R.transpose();
}

TEST(Bounds, IsotropicExactIsTheChiSquareRadius) {
  const Eigen::Matrix2d c = rotated(0.01, 0.01, 0.3);  // 1 cm each way
  // P(|e| <= r) = 1 - exp(-r^2 / (2 sigma^2)) for an isotropic error.
  EXPECT_NEAR(bound_95(c, BoundMethod::kExact), 0.01 * std::sqrt(-2.0 * std::log(0.05)), 1e-9);
  EXPECT_NEAR(bound_95(c, BoundMethod::kChi2MaxEigen), bound_95(c, BoundMethod::kExact), 1e-9);
  // Seed 004's 2 sigma covers only 1 - exp(-2) of an isotropic error.
  EXPECT_NEAR(probability_within(c, bound_95(c, BoundMethod::kPaper)), 1.0 - std::exp(-2.0), 1e-6);
}

TEST(Bounds, ElongatedApproachesTheOneAxisQuantile) {
  const Eigen::Matrix2d c = rotated(0.05, 0.00005, 1.0);  // 1000:1
  EXPECT_NEAR(bound_95(c, BoundMethod::kExact), 1.959964 * 0.05, 1e-5);
  const Eigen::Matrix2d flat = rotated(0.05, 0.0, 0.2);  // singular
  EXPECT_NEAR(bound_95(flat, BoundMethod::kExact), 1.959964 * 0.05, 1e-6);
  EXPECT_EQ(bound_95(Eigen::Matrix2d::Zero(), BoundMethod::kExact), 0.0);
}

TEST(Bounds, ExactRadiusHoldsNinetyFivePercentByMonteCarlo) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (const double ratio : {1.0, 0.5, 0.2, 0.05}) {
    const double s1 = 0.02, s2 = 0.02 * ratio, angle = 0.7;
    const Eigen::Matrix2d c = rotated(s1, s2, angle);
    const double r = bound_95(c, BoundMethod::kExact);
    EXPECT_NEAR(probability_within(c, r), 0.95, 1e-9);
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(angle).toRotationMatrix();
    int inside = 0;
    constexpr int kDraws = 200000;
    for (int i = 0; i < kDraws; ++i) {
      const Eigen::Vector2d e = R * Eigen::Vector2d(s1 * n01(rng), s2 * n01(rng));
      if (e.norm() <= r) ++inside;
    }
    // Binomial standard deviation at 200,000 draws: 0.0005.
    EXPECT_NEAR(static_cast<double>(inside) / kDraws, 0.95, 0.0025) << "ratio " << ratio;
    // The ordering of the three bounds (bounds.hpp).
    EXPECT_GE(bound_95(c, BoundMethod::kChi2MaxEigen), r - 1e-12);
    EXPECT_GE(r, 1.959963 * s1);
    EXPECT_NEAR(bound_95(c, BoundMethod::kPaper), 2.0 * s1, 1e-12);
  }
}

TEST(Bounds, DoesNotDependOnOrientation) {
  const double a = bound_95(rotated(0.03, 0.01, 0.0), BoundMethod::kExact);
  for (double angle : {0.4, 1.3, 2.9}) {
    EXPECT_NEAR(bound_95(rotated(0.03, 0.01, angle), BoundMethod::kExact), a, 1e-10);
  }
}

TEST(Bounds, ParsesTheMethodNames) {
  EXPECT_EQ(parse_bound_method("exact"), BoundMethod::kExact);
  EXPECT_EQ(parse_bound_method("chi2_max_eigen"), BoundMethod::kChi2MaxEigen);
  EXPECT_EQ(parse_bound_method("paper"), BoundMethod::kPaper);
  EXPECT_FALSE(parse_bound_method("2sigma"));
}

}  // namespace
}  // namespace traverse::annotator
