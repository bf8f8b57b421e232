#include "degeneracy.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace traverse {
namespace {

// S maps the scaled coordinates (x, y, L theta) to (x, y, theta).
Eigen::Matrix3d scale(double length_m) {
  return Eigen::Vector3d(1.0, 1.0, 1.0 / length_m).asDiagonal();
}

}  // namespace

double points_rms_range_m(const std::vector<Eigen::Vector2d>& points_base) {
  if (points_base.empty()) return 1.0;
  double range2 = 0.0;
  for (const auto& p : points_base) range2 += p.squaredNorm();
  return std::max(1e-3, std::sqrt(range2 / points_base.size()));
}

Degeneracy analyse_degeneracy(const Eigen::Matrix3d& information, double length_m,
                              double min_ratio) {
  Degeneracy d;
  d.length_m = length_m;
  const Eigen::Matrix3d S = scale(length_m);
  const Eigen::Matrix3d scaled = S * information * S;  // I' = S^T I S (S diagonal)
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 * (scaled + scaled.transpose()));
  d.eigenvalues = eigen.eigenvalues();
  d.directions_scaled = eigen.eigenvectors();
  const double largest = std::max(d.eigenvalues(2), 0.0);
  d.ratio = largest > 0.0 ? std::max(0.0, d.eigenvalues(0)) / largest : 0.0;
  Eigen::Matrix3d well = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = d.directions_scaled.col(i);
    if (largest > 0.0 && d.eigenvalues(i) >= min_ratio * largest) {
      well += v * v.transpose();
    } else {
      ++d.directions;
    }
  }
  // In (x, y, theta): xi = S xi', so P = S P' S^-1.
  d.projector = S * well * S.inverse();
  return d;
}

Pose2 remap(const Degeneracy& d, const Pose2& T_predicted, const Pose2& T_matched) {
  if (d.directions == 0) return T_matched;
  Eigen::Vector3d delta = T_matched.vector() - T_predicted.vector();
  delta.z() = wrap_angle(delta.z());
  const Eigen::Vector3d xi = T_predicted.vector() + d.projector * delta;
  return Pose2(xi.x(), xi.y(), wrap_angle(xi.z()));
}

Eigen::Matrix3d remapped_covariance(const Degeneracy& d,
                                    const Eigen::Matrix3d& covariance_predicted) {
  const Eigen::Matrix3d S = scale(d.length_m);
  const Eigen::Matrix3d S_inv = S.inverse();
  // Scaled: C' = S^-1 C S^-T; each eigen-direction v of I' gets 1 / lambda (well-determined) or
  // v^T C'_pred v (degenerate).
  const Eigen::Matrix3d predicted_scaled = S_inv * covariance_predicted * S_inv;
  Eigen::Matrix3d scaled = Eigen::Matrix3d::Zero();
  const double largest = std::max(d.eigenvalues(2), 0.0);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = d.directions_scaled.col(i);
    const bool degenerate = i < d.directions;
    const double variance = degenerate ? v.dot(predicted_scaled * v)
                                       : 1.0 / std::max(d.eigenvalues(i), 1e-12 * largest);
    scaled += variance * v * v.transpose();
  }
  return S * scaled * S;
}

Eigen::Matrix3d held_covariance(const Degeneracy& d, const Eigen::Matrix3d& covariance_matched,
                                const Eigen::Matrix3d& covariance_predicted) {
  const Eigen::Matrix3d S = scale(d.length_m);
  const Eigen::Matrix3d S_inv = S.inverse();
  const Eigen::Matrix3d matched = S_inv * covariance_matched * S_inv;
  const Eigen::Matrix3d predicted = S_inv * covariance_predicted * S_inv;
  Eigen::Matrix3d well = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d held = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = d.directions_scaled.col(i);
    if (i < d.directions) {
      held += v.dot(predicted * v) * v * v.transpose();
    } else {
      well += v * v.transpose();
    }
  }
  return S * (well * matched * well + held) * S;
}

Eigen::Matrix3d opened_covariance(const Degeneracy& d, const Eigen::Matrix3d& covariance,
                                  double sigma_m) {
  const Eigen::Matrix3d S = scale(d.length_m);
  Eigen::Matrix3d opened = Eigen::Matrix3d::Zero();
  for (int i = 0; i < d.directions; ++i) {
    const Eigen::Vector3d v = d.directions_scaled.col(i);
    const double variance = 1.0 / std::max(d.eigenvalues(i), 1.0 / (sigma_m * sigma_m));
    opened += variance * v * v.transpose();
  }
  return covariance + S * opened * S;
}

}  // namespace traverse
