#include "metrics.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace traverse::evaluator {
namespace {

// Estimated minus true translation of the motion from a to b, each in its own start pose's frame.
Eigen::Vector2d step_translation_error(const Pose2& ref_a, const Pose2& ref_b, const Pose2& est_a,
                                       const Pose2& est_b) {
  return between(est_a, est_b).translation() - between(ref_a, ref_b).translation();
}

// Length of the difference between two relative motions' translations.
double relative_translation_error(const Pose2& ref_a, const Pose2& ref_b, const Pose2& est_a,
                                  const Pose2& est_b) {
  return step_translation_error(ref_a, ref_b, est_a, est_b).norm();
}

}  // namespace

ErrorStats error_stats(const std::vector<double>& magnitudes) {
  ErrorStats s;
  if (magnitudes.empty()) return s;
  const double n = static_cast<double>(magnitudes.size());
  double sum = 0.0, sum_sq = 0.0;
  for (double e : magnitudes) {
    sum += e;
    sum_sq += e * e;
    s.max = std::max(s.max, e);
  }
  const double mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0.0;
  for (double e : magnitudes) var += (e - mean) * (e - mean);
  s.sd = std::sqrt(var / n);
  return s;
}

RelativeError relative_pose_error(const std::vector<Pose2>& est, const std::vector<Pose2>& ref,
                                  const std::vector<double>& travel_m, double distance_m) {
  RelativeError r;
  double sum_sq = 0.0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    // travel_m is non-decreasing, so the partner j only moves forward.
    j = std::max(j, i + 1);
    while (j < est.size() && travel_m[j] - travel_m[i] < distance_m) ++j;
    if (j >= est.size()) break;
    const double e = relative_translation_error(ref[i], ref[j], est[i], est[j]);
    sum_sq += e * e;
    ++r.pairs;
  }
  if (r.pairs > 0) r.rms_m = std::sqrt(sum_sq / static_cast<double>(r.pairs));
  return r;
}

Jump max_jump(const std::vector<Pose2>& est, const std::vector<Pose2>& ref) {
  Jump jump;
  for (std::size_t k = 1; k < est.size(); ++k) {
    const double e = relative_translation_error(ref[k - 1], ref[k], est[k - 1], est[k]);
    if (e > jump.step_error_m) jump = {e, k};
  }
  return jump;
}

StepConsistency step_consistency(const std::vector<Pose2>& est,
                                 const std::vector<Eigen::Matrix3d>& cov,
                                 const std::vector<Pose2>& ref) {
  // The chi-square quantile with 2 degrees of freedom at 99 %.
  constexpr double kChi2_2dof_99 = 9.21;
  StepConsistency r;
  std::vector<double> nees;
  for (std::size_t k = 1; k < est.size(); ++k) {
    if (cov[k - 1].isZero() || cov[k].isZero()) continue;
    const Pose2& a = est[k - 1];
    const Eigen::Vector2d step = between(a, est[k]).translation();
    const Eigen::Vector2d e = step_translation_error(ref[k - 1], ref[k], a, est[k]);
    const Eigen::Matrix2d R = a.rotation();
    const Eigen::Vector2d swing(step.y(), -step.x());  // d(step) / d(theta_a)
    const Eigen::Matrix2d S =
        R.transpose() * (cov[k - 1].topLeftCorner<2, 2>() + cov[k].topLeftCorner<2, 2>()) * R +
        cov[k - 1](2, 2) * swing * swing.transpose();
    const Eigen::LLT<Eigen::Matrix2d> llt(S);
    if (llt.info() != Eigen::Success || !(S.determinant() > 0.0)) continue;
    nees.push_back(e.dot(llt.solve(e)));
  }
  r.steps = nees.size();
  if (nees.empty()) return r;
  r.outside_99_fraction =
      static_cast<double>(
          std::count_if(nees.begin(), nees.end(), [&](double d) { return d > kChi2_2dof_99; })) /
      static_cast<double>(nees.size());
  std::nth_element(nees.begin(), nees.begin() + nees.size() / 2, nees.end());
  r.nees_median = nees[nees.size() / 2];
  return r;
}

}  // namespace traverse::evaluator
