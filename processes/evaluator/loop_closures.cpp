#include "loop_closures.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "median.hpp"

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

// The truth of one closure: T_true, and the covariance of T_true's own error (right-perturbation
// in T_true's frame; zero for a reference taken as exact).
struct Truth {
  Pose2 T_true;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  std::optional<Pose2> frontend;  // the frontend's own F(from)^-1 F(to), when it is known
};

// The pose graph's error of a measurement Z against the truth: t2v(Z^-1 T_true), in Z's frame
// (between() gives the translation there), the angle wrapped.
Eigen::Vector3d graph_error(const Pose2& Z, const Pose2& T_true) {
  const Pose2 E = between(Z, T_true);
  return Eigen::Vector3d(E.x(), E.y(), wrap_angle(E.theta()));
}

// The check against any source of truth: `truth` gives a closure's Truth, or nullopt.
template <class TruthOf>
ClosureEvaluation check_against(const std::vector<LoopClosure>& closures, const TruthOf& truth_of,
                                double false_sigmas) {
  ClosureEvaluation ev;
  ev.closures = closures.size();
  double sum_sq_m2 = 0.0;
  std::size_t matched = 0;
  for (const LoopClosure& c : closures) {
    ClosureCheck check;
    check.closure = c;
    check.sigma = c.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
    const std::optional<Truth> truth = truth_of(c);
    if (!truth) {
      ++ev.unmatched;
      ev.checks.push_back(check);
      continue;
    }
    check.matched = true;
    check.T_true = truth->T_true;
    check.error = graph_error(c.T_from_to, check.T_true);
    if (truth->frontend) check.frontend_error = graph_error(*truth->frontend, check.T_true);
    const double error_m = check.error.head<2>().norm();
    ++matched;
    sum_sq_m2 += error_m * error_m;
    ev.max_error_m = std::max(ev.max_error_m.value_or(0.0), error_m);
    check.mahalanobis = mahalanobis(check.error, c.covariance + truth->covariance);
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

// The pose of `trajectory` (sorted, not empty) nearest `utime`, however far.
const Pose2& nearest(const Trajectory& trajectory, int64_t utime) {
  return pose_at(trajectory, utime, std::numeric_limits<int64_t>::max())->pose;
}

// The frontend's error over a bridge: the mean of e e^T over the relations whose scans lie within
// `window_us` of each other, e = t2v(R^-1 F(t1)^-1 F(t2)), made isotropic in x and y (a bridge
// is used in any heading). Zero with fewer than 10 such relations: the truth is then taken as
// exact.
Eigen::Matrix3d bridge_covariance(const Trajectory& frontend,
                                  const std::vector<Relation>& relations, int64_t window_us) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  int n = 0;
  for (const Relation& r : relations) {
    if (std::abs(r.t2_utime - r.t1_utime) > window_us) continue;
    const Pose2 F = between(nearest(frontend, r.t1_utime), nearest(frontend, r.t2_utime));
    const Eigen::Vector3d e = graph_error(r.T_1_2, F);
    sum += e * e.transpose();
    ++n;
  }
  if (n < 10) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d mean = sum / n;
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  c(0, 0) = c(1, 1) = 0.5 * (mean(0, 0) + mean(1, 1));
  c(2, 2) = mean(2, 2);
  return c;
}

// The relation whose ends lie nearest a closure's key poses (summed), either way round: its scans'
// times ta (near `from`) and tb (near `to`) and the truth between them, R_a_b.
struct Reach {
  int64_t ta = 0, tb = 0;
  Pose2 R_a_b;
};

// Nullopt when no relation has an end within `window_us` of each key pose.
std::optional<Reach> nearest_relation(const LoopClosure& c, const std::vector<Relation>& relations,
                                      int64_t window_us) {
  std::optional<int64_t> best_us;
  Reach reach;
  for (const Relation& r : relations) {
    for (const bool reversed : {false, true}) {
      const int64_t a = reversed ? r.t2_utime : r.t1_utime;
      const int64_t b = reversed ? r.t1_utime : r.t2_utime;
      const int64_t da = std::abs(a - c.from_utime), db = std::abs(b - c.to_utime);
      if (da > window_us || db > window_us || (best_us && da + db >= *best_us)) continue;
      best_us = da + db;
      reach = {a, b, reversed ? r.T_1_2.inverse() : r.T_1_2};
    }
  }
  if (!best_us) return std::nullopt;
  return reach;
}

}  // namespace

ClosureEvaluation check_closures(const std::vector<LoopClosure>& closures, Trajectory reference,
                                 const MatchConfig& match, double false_sigmas) {
  sort_unique(reference);
  const ReferenceInterpolator interpolator(reference, match);
  return check_against(
      closures,
      [&](const LoopClosure& c) -> std::optional<Truth> {
        const auto from = interpolator.at(c.from_utime);
        const auto to = interpolator.at(c.to_utime);
        if (!from || !to) return std::nullopt;
        return Truth{between(from->pose, to->pose), Eigen::Matrix3d::Zero(), std::nullopt};
      },
      false_sigmas);
}

ClosureEvaluation check_closures_by_relations(const std::vector<LoopClosure>& closures,
                                              Trajectory frontend,
                                              const std::vector<Relation>& relations,
                                              int64_t window_us, double false_sigmas) {
  sort_unique(frontend);
  const Eigen::Matrix3d bridge = frontend.empty()
                                     ? Eigen::Matrix3d::Zero()
                                     : bridge_covariance(frontend, relations, window_us);
  ClosureEvaluation ev = check_against(
      closures,
      [&](const LoopClosure& c) -> std::optional<Truth> {
        if (frontend.empty()) return std::nullopt;
        const std::optional<Reach> reach = nearest_relation(c, relations, window_us);
        if (!reach) return std::nullopt;
        const Pose2& F_from = nearest(frontend, c.from_utime);
        const Pose2& F_to = nearest(frontend, c.to_utime);
        const Pose2 to_a = between(F_from, nearest(frontend, reach->ta));
        const Pose2 from_b = between(nearest(frontend, reach->tb), F_to);
        // T_true = to_a * B, B = R * from_b. An error of to_a (right-perturbation d) moves T_true
        // by Ad(B^-1) d in its own frame; an error of from_b by itself.
        Truth truth{to_a * reach->R_a_b * from_b, Eigen::Matrix3d::Zero(), between(F_from, F_to)};
        const Eigen::Matrix3d Ad = (reach->R_a_b * from_b).inverse().adjoint();
        if (reach->ta != c.from_utime) truth.covariance += Ad * bridge * Ad.transpose();
        if (reach->tb != c.to_utime) truth.covariance += bridge;
        return truth;
      },
      false_sigmas);
  ev.bridge_covariance = bridge;
  return ev;
}

ClosureMedians medians(const ClosureEvaluation& evaluation) {
  std::vector<double> error_m, error_rad, mahalanobis, frontend_m, frontend_rad;
  ClosureMedians m;
  for (const ClosureCheck& c : evaluation.checks) {
    if (!c.matched) continue;
    ++m.checked;
    error_m.push_back(c.error.head<2>().norm());
    error_rad.push_back(std::abs(c.error.z()));
    m.max_error_rad = std::max(m.max_error_rad.value_or(0.0), error_rad.back());
    if (c.mahalanobis) mahalanobis.push_back(*c.mahalanobis);
    if (!c.frontend_error) continue;
    frontend_m.push_back(c.frontend_error->head<2>().norm());
    frontend_rad.push_back(std::abs(c.frontend_error->z()));
    // Nearer by over 1 um: an exact closure beside an exact frontend is not nearer.
    if (error_m.back() + 1e-6 < frontend_m.back()) ++m.closure_nearer;
  }
  m.error_m = median(error_m);
  m.error_rad = median(error_rad);
  m.mahalanobis = median(mahalanobis);
  m.frontend_error_m = median(frontend_m);
  m.frontend_error_rad = median(frontend_rad);
  return m;
}

}  // namespace traverse::evaluator
