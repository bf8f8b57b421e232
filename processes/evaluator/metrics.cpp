#include "metrics.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::evaluator {
namespace {

// Translational part of the difference between two relative motions.
double relative_translation_error(const Pose2& ref_a, const Pose2& ref_b, const Pose2& est_a,
                                  const Pose2& est_b) {
  const Pose2 error = between(between(ref_a, ref_b), between(est_a, est_b));
  return error.translation().norm();
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

}  // namespace traverse::evaluator
