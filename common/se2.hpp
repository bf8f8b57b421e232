// SE(2) rigid motions in the plane: composition, inverse, exponential and logarithm maps,
// interpolation, angle wrapping, and the Jacobians the optimisers need.
//
// A Pose2 named T_a_b maps points from frame b into frame a: p_a = T_a_b * p_b. Angles are in
// radians, lengths in metres. exp/log follow the usual closed form (e.g. Sola et al., "A micro Lie
// theory for state estimation in robotics", 2018, example 2 on SE(2)); tangent vectors are ordered
// (x, y, theta).
#pragma once

#include <Eigen/Core>

namespace traverse {

// Wraps an angle to (-pi, pi].
double wrap_angle(double a);

class Pose2 {
 public:
  Pose2() = default;
  Pose2(double x, double y, double theta);

  double x() const { return t_.x(); }
  double y() const { return t_.y(); }
  double theta() const { return theta_; }
  const Eigen::Vector2d& translation() const { return t_; }
  Eigen::Matrix2d rotation() const;
  Eigen::Vector3d vector() const { return {t_.x(), t_.y(), theta_}; }

  Pose2 operator*(const Pose2& other) const;
  Eigen::Vector2d operator*(const Eigen::Vector2d& p) const;
  Pose2 inverse() const;

  // Exponential map from the tangent (vx, vy, omega) to the group.
  static Pose2 exp(const Eigen::Vector3d& xi);
  // Logarithm map, the inverse of exp for |theta| < pi.
  Eigen::Vector3d log() const;

  // Adjoint matrix: Ad(T) xi = log(T exp(xi) T^-1) to first order.
  Eigen::Matrix3d adjoint() const;

 private:
  Eigen::Vector2d t_ = Eigen::Vector2d::Zero();
  double theta_ = 0.0;
};

// Geodesic interpolation: a * exp(s * log(a^-1 b)), s in [0, 1].
Pose2 interpolate(const Pose2& a, const Pose2& b, double s);

// Relative motion a^-1 * b (b expressed in the frame of a).
Pose2 between(const Pose2& a, const Pose2& b);

// Jacobians of c = a * b on the (x, y, theta) parameterisation (not the Lie tangent):
// dc/da and dc/db, as used by pose-graph optimisation with additive updates.
Eigen::Matrix3d compose_jacobian_a(const Pose2& a, const Pose2& b);
Eigen::Matrix3d compose_jacobian_b(const Pose2& a, const Pose2& b);

// Jacobians of e = between(a, b) on the (x, y, theta) parameterisation: de/da and de/db.
Eigen::Matrix3d between_jacobian_a(const Pose2& a, const Pose2& b);
Eigen::Matrix3d between_jacobian_b(const Pose2& a, const Pose2& b);

// A covariance of (x, y, theta) in a frame turned by R (the x, y part turns, theta does not):
// J C J^T with J = diag(R, 1). R = T_a_b.rotation() takes a covariance from frame b into a.
Eigen::Matrix3d rotate_covariance(const Eigen::Matrix3d& covariance, const Eigen::Matrix2d& R);

}  // namespace traverse
