#include "loop_closures.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace traverse::evaluator {

void LoopClosureSet::add(const LoopClosure& closure) {
  const auto [it, inserted] = by_ids_.insert_or_assign({closure.from_id, closure.to_id}, closure);
  if (!inserted) ++repeated_;
}

std::vector<LoopClosure> LoopClosureSet::closures() const {
  std::vector<LoopClosure> out;
  out.reserve(by_ids_.size());
  for (const auto& [ids, c] : by_ids_) out.push_back(c);
  return out;
}

namespace {

// sqrt(e^T C^-1 e), or nullopt when C is not finite, symmetric and positive definite.
std::optional<double> mahalanobis(const Eigen::Vector3d& e, const Eigen::Matrix3d& C) {
  if (!C.allFinite() || !C.isApprox(C.transpose(), 1e-9)) return std::nullopt;
  const Eigen::LLT<Eigen::Matrix3d> llt(C);
  if (llt.info() != Eigen::Success) return std::nullopt;
  // With C = L L^T: e^T C^-1 e = |L^-1 e|^2.
  const Eigen::Vector3d w = llt.matrixL().solve(e);
  return w.norm();
}

}  // namespace

ClosureEvaluation check_closures(const std::vector<LoopClosure>& closures, Trajectory reference,
                                 const MatchConfig& match, double false_sigmas) {
  sort_unique(reference);
  const ReferenceInterpolator interpolator(reference, match);
  ClosureEvaluation ev;
  ev.closures = closures.size();
  double sum_sq_m2 = 0.0;
  std::size_t matched = 0;
  for (const LoopClosure& c : closures) {
    ClosureCheck check;
    check.closure = c;
    check.sigma = c.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    const auto from = interpolator.at(c.from_utime);
    const auto to = interpolator.at(c.to_utime);
    if (!from || !to) {
      ++ev.unmatched;
      ev.checks.push_back(check);
      continue;
    }
    check.matched = true;
    check.T_true = between(from->pose, to->pose);
    // e = t2v(Z^-1 T_true): between() gives the translation in Z's frame; the angle is wrapped.
    const Pose2 E = between(c.T_from_to, check.T_true);
    check.error = Eigen::Vector3d(E.x(), E.y(), wrap_angle(E.theta()));
    const double error_m = check.error.head<2>().norm();
    ++matched;
    sum_sq_m2 += error_m * error_m;
    ev.max_error_m = std::max(ev.max_error_m.value_or(0.0), error_m);
    check.mahalanobis = mahalanobis(check.error, c.covariance);
    if (!check.mahalanobis) {
      ++ev.bad_covariance;
    } else {
      ev.max_mahalanobis = std::max(ev.max_mahalanobis.value_or(0.0), *check.mahalanobis);
      check.is_false = *check.mahalanobis > false_sigmas;
      if (check.is_false) ++ev.false_closures;
    }
    ev.checks.push_back(check);
  }
  if (matched > 0) ev.rms_error_m = std::sqrt(sum_sq_m2 / static_cast<double>(matched));
  return ev;
}

}  // namespace traverse::evaluator
