#include "icp_matcher.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

namespace traverse::frontend {
namespace {

// One linearisation at T: the data term's J^T W J and J^T W r, and its statistics.
struct Linearised {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  double weight_sum = 0.0, weighted_r2 = 0.0, r2 = 0.0;
  int pairs = 0;
};

Linearised linearise(const PointMap& map, const std::vector<Eigen::Vector2d>& points,
                     const Pose2& T, double max_distance_m, double kernel_m) {
  Linearised l;
  const Eigen::Matrix2d R = T.rotation();
  for (const Eigen::Vector2d& p : points) {
    const Eigen::Vector2d Rp = R * p;
    const Eigen::Vector2d q = Rp + T.translation();
    const MapPoint* m = map.nearest(q, max_distance_m);
    if (!m) continue;
    const double r = m->n.dot(q - m->p);
    // d q / d theta = (-Rp_y, Rp_x).
    const Eigen::Vector3d J(m->n.x(), m->n.y(), m->n.x() * -Rp.y() + m->n.y() * Rp.x());
    const double u = r / kernel_m;
    const double w = 1.0 / (1.0 + u * u);  // Cauchy
    l.H += w * J * J.transpose();
    l.g += w * r * J;
    l.weight_sum += w;
    l.weighted_r2 += w * r * r;
    l.r2 += r * r;
    ++l.pairs;
  }
  return l;
}

Eigen::Vector3d difference(const Pose2& a, const Pose2& b) {
  return {a.x() - b.x(), a.y() - b.y(), wrap_angle(a.theta() - b.theta())};
}

}  // namespace

IcpResult match_point_to_line(const PointMap& map, const std::vector<Eigen::Vector2d>& points,
                              const Pose2& T_start, const Pose2& T_prior,
                              const Eigen::Matrix3d& prior_information, const IcpConfig& config) {
  IcpResult result;
  Pose2 T = T_start;
  double distance = config.max_correspondence_m;
  Linearised l;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int it = 0; it < config.max_iterations; ++it) {
    l = linearise(map, points, T, distance, config.kernel_m);
    ++result.iterations;
    const Eigen::Matrix3d H = l.H + prior_information;
    const Eigen::Vector3d g = l.g + prior_information * difference(T, T_prior);
    const Eigen::LDLT<Eigen::Matrix3d> solver(H);
    if (l.pairs < 3 || solver.info() != Eigen::Success) break;
    Eigen::Vector3d step = -solver.solve(g);
    // A step that undoes the previous one: a point entering and leaving the gate in turn, the
    // pose between the two is as good as either (without this the pairs flip for ever).
    const bool flipping = (step + previous).norm() < 0.1 * step.norm();
    if (flipping) step *= 0.5;
    previous = step;
    T = Pose2(T.x() + step.x(), T.y() + step.y(), T.theta() + step.z());
    const bool small = flipping || (step.head<2>().norm() < config.convergence_m &&
                                    std::abs(step.z()) < config.convergence_rad);
    if (!small) continue;
    if (distance <= config.final_correspondence_m) {
      result.converged = true;
      break;
    }
    distance = config.final_correspondence_m;
    previous.setZero();
  }
  // The statistics and covariance at the result, with the final pairing.
  l = linearise(map, points, T, config.final_correspondence_m, config.kernel_m);
  result.T_map_base = T;
  result.correspondences = l.pairs;
  result.inlier_fraction = points.empty() ? 0.0 : static_cast<double>(l.pairs) / points.size();
  result.residual_rms_m = l.pairs > 0 ? std::sqrt(l.r2 / l.pairs) : 0.0;
  const double dof = l.weight_sum - 3.0;
  const double sigma2 = std::max(config.min_residual_sigma_m * config.min_residual_sigma_m,
                                 dof > 0.0 ? l.weighted_r2 / dof : 0.0);
  const Eigen::Matrix3d information = l.H / sigma2 + prior_information;
  result.covariance = information.inverse();
  return result;
}

}  // namespace traverse::frontend
