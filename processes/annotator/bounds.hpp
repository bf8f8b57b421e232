// 95 % bounds on a 2D position error from its covariance (seed 004, section 3.2, corrected).
//
// Seed 004 takes the largest eigenvalue lambda_max of the translational covariance and reports
// 2 sqrt(lambda_max). That is a 95 % bound along one axis (the normal quantile 1.96, rounded), not
// on the length of a 2D error: for an isotropic covariance P(|e| <= 2 sqrt(lambda)) =
// 1 - exp(-2) = 86.5 %. Three bounds are offered:
//   - kExact (default): the radius r with P(|e| <= r) = 0.95 for e ~ N(0, Sigma), found
//     numerically. In polar coordinates (e = rho (cos phi, sin phi) along Sigma's eigenvectors,
//     a(phi) = cos^2 phi / lambda_1 + sin^2 phi / lambda_2) the density integrates in rho in
//     closed form:
//       P(|e| <= r) = 1 / (2 pi sqrt(lambda_1 lambda_2)) * int_0^{2 pi} (1 - exp(-r^2 a / 2)) / a
//       dphi,
//     a smooth periodic integrand, so the trapezoidal rule converges geometrically; r is then
//     found by bisection between 1.96 sqrt(lambda_max) (the one-axis bound, reached when
//     lambda_2 -> 0) and sqrt(chi2_2(0.95) lambda_max) (reached when lambda_1 = lambda_2).
//   - kChi2MaxEigen: sqrt(chi2_2(0.95) lambda_max) = sqrt(5.991 lambda_max), the circle around the
//     95 % ellipse: exact for an isotropic covariance, conservative (covers more than 95 %) for an
//     anisotropic one, up to 2.45 / 1.96 = 1.25 times the exact radius.
//   - kPaper: seed 004's 2 sqrt(lambda_max), kept for comparison: between the two above, so
//     optimistic (86.5 %) for an isotropic covariance and slightly conservative for a very
//     elongated one.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

namespace traverse::annotator {

enum class BoundMethod { kExact, kChi2MaxEigen, kPaper };

// "exact", "chi2_max_eigen" or "paper"; nullopt for anything else.
std::optional<BoundMethod> parse_bound_method(const std::string& name);

inline constexpr double kConfidence = 0.95;
// chi-square quantile with two degrees of freedom at 95 %: -2 ln(1 - 0.95).
inline constexpr double kChi2TwoDof95 = 5.991464547107979;
// Standard normal quantile at 97.5 %: the two-sided 95 % bound along one axis.
inline constexpr double kNormal975 = 1.959963984540054;

// Probability that |e| <= r for e ~ N(0, Sigma), Sigma a 2x2 covariance [m^2], r [m].
double probability_within(const Eigen::Matrix2d& covariance, double radius_m);

// The 95 % bound [m] of a 2D position error with covariance [m^2]; 0 for a zero covariance.
double bound_95(const Eigen::Matrix2d& covariance, BoundMethod method);

}  // namespace traverse::annotator
