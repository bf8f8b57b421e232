#include "bounds.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace traverse::annotator {
namespace {

// Eigenvalues (largest first), clamped at zero against rounding.
std::pair<double, double> eigenvalues(const Eigen::Matrix2d& covariance) {
  const Eigen::Matrix2d sym = 0.5 * (covariance + covariance.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(sym, Eigen::EigenvaluesOnly);
  const Eigen::Vector2d l = solver.eigenvalues();  // increasing
  return {std::max(l[1], 0.0), std::max(l[0], 0.0)};
}

// Below this ratio lambda_2 / lambda_1 the error is taken as one-dimensional: the second axis
// changes the radius by a relative amount of the order of the ratio.
constexpr double kOneAxisRatio = 1e-6;

// P(lambda_1 z_1^2 + lambda_2 z_2^2 <= r^2), lambda_1 >= lambda_2 > 0 (see bounds.hpp), and its
// derivative in r in `density`.
double probability_within(double l1, double l2, double r, double* density = nullptr) {
  // The integrand peaks around phi = 0 with a width of about sqrt(lambda_2 / lambda_1); the
  // trapezoidal rule on a periodic analytic function is accurate once the step is well below it.
  const int steps = 64 + static_cast<int>(std::ceil(16.0 * std::sqrt(l1 / l2)));
  // The integrand has period pi and is symmetric: integrate over [0, pi/2] and multiply by 4.
  const double h = 0.5 * std::numbers::pi / steps;
  double sum = 0.0, dsum = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const double phi = k * h;
    const double c = std::cos(phi), s = std::sin(phi);
    const double a = c * c / l1 + s * s / l2;
    const double g = std::exp(-0.5 * r * r * a);
    const double w = (k == 0 || k == steps) ? 0.5 : 1.0;
    sum += w * -std::expm1(-0.5 * r * r * a) / a;
    dsum += w * r * g;
  }
  const double norm = 4.0 * h / (2.0 * std::numbers::pi * std::sqrt(l1 * l2));
  if (density) *density = norm * dsum;
  return norm * sum;
}

double exact_radius(double l1, double l2) {
  // Along one axis only: the two-sided normal quantile.
  if (l2 <= kOneAxisRatio * l1) return kNormal975 * std::sqrt(l1);
  // Newton's method on P(r) = 0.95 inside the bracket [1.96, 2.45] sqrt(lambda_1), bisecting
  // whenever a step would leave it; P is increasing, so the bracket always holds the root.
  double lo = kNormal975 * std::sqrt(l1), hi = std::sqrt(kChi2TwoDof95 * l1);
  double r = 0.5 * (lo + hi);
  for (int i = 0; i < 100; ++i) {
    double density = 0.0;
    const double f = probability_within(l1, l2, r, &density) - kConfidence;
    (f < 0.0 ? lo : hi) = r;
    double next = density > 0.0 ? r - f / density : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - r) <= 1e-12 * r) return next;
    r = next;
  }
  return r;
}

}  // namespace

std::optional<BoundMethod> parse_bound_method(const std::string& name) {
  if (name == "exact") return BoundMethod::kExact;
  if (name == "chi2_max_eigen") return BoundMethod::kChi2MaxEigen;
  if (name == "paper") return BoundMethod::kPaper;
  return std::nullopt;
}

double probability_within(const Eigen::Matrix2d& covariance, double radius_m) {
  const auto [l1, l2] = eigenvalues(covariance);
  if (l1 <= 0.0) return 1.0;
  if (l2 <= kOneAxisRatio * l1) return std::erf(radius_m / std::sqrt(2.0 * l1));
  return probability_within(l1, l2, radius_m);
}

double bound_95(const Eigen::Matrix2d& covariance, BoundMethod method) {
  const auto [l1, l2] = eigenvalues(covariance);
  if (l1 <= 0.0) return 0.0;
  switch (method) {
    case BoundMethod::kChi2MaxEigen:
      return std::sqrt(kChi2TwoDof95 * l1);
    case BoundMethod::kPaper:
      return 2.0 * std::sqrt(l1);
    case BoundMethod::kExact:
      break;
  }
  return exact_radius(l1, l2);
}

}  // namespace traverse::annotator
