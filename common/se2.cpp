#include "se2.hpp"

#include <cmath>

namespace traverse {

double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * M_PI);  // in [-pi, pi]
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

Pose2::Pose2(double x, double y, double theta) : t_(x, y), theta_(wrap_angle(theta)) {}

Eigen::Matrix2d Pose2::rotation() const {
  const double c = std::cos(theta_), s = std::sin(theta_);
  Eigen::Matrix2d r;
  r << c, -s, s, c;
  return r;
}

Pose2 Pose2::operator*(const Pose2& o) const {
  const Eigen::Vector2d t = t_ + rotation() * o.t_;
  return Pose2(t.x(), t.y(), theta_ + o.theta_);
}

Eigen::Vector2d Pose2::operator*(const Eigen::Vector2d& p) const { return t_ + rotation() * p; }

Pose2 Pose2::inverse() const {
  const Eigen::Vector2d t = -(rotation().transpose() * t_);
  return Pose2(t.x(), t.y(), -theta_);
}

// V(theta) = [sin/theta, -(1-cos)/theta; (1-cos)/theta, sin/theta], with Taylor series near zero.
static void v_coefficients(double theta, double& a, double& b) {
  if (std::abs(theta) < 1e-5) {
    const double t2 = theta * theta;
    a = 1.0 - t2 / 6.0;
    b = theta / 2.0 - theta * t2 / 24.0;
  } else {
    a = std::sin(theta) / theta;
    b = (1.0 - std::cos(theta)) / theta;
  }
}

Pose2 Pose2::exp(const Eigen::Vector3d& xi) {
  double a, b;
  v_coefficients(xi.z(), a, b);
  return Pose2(a * xi.x() - b * xi.y(), b * xi.x() + a * xi.y(), xi.z());
}

Eigen::Vector3d Pose2::log() const {
  double a, b;
  v_coefficients(theta_, a, b);
  // Inverse of V = [a -b; b a] is [a b; -b a] / (a^2 + b^2).
  const double d = a * a + b * b;
  return {(a * t_.x() + b * t_.y()) / d, (-b * t_.x() + a * t_.y()) / d, theta_};
}

Eigen::Matrix3d Pose2::adjoint() const {
  Eigen::Matrix3d ad = Eigen::Matrix3d::Identity();
  ad.topLeftCorner<2, 2>() = rotation();
  ad(0, 2) = t_.y();
  ad(1, 2) = -t_.x();
  return ad;
}

Pose2 interpolate(const Pose2& a, const Pose2& b, double s) {
  return a * Pose2::exp(s * between(a, b).log());
}

Pose2 between(const Pose2& a, const Pose2& b) { return a.inverse() * b; }

Eigen::Matrix3d compose_jacobian_a(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.theta()), s = std::sin(a.theta());
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j(0, 2) = -s * b.x() - c * b.y();
  j(1, 2) = c * b.x() - s * b.y();
  return j;
}

Eigen::Matrix3d compose_jacobian_b(const Pose2& a, const Pose2&) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j.topLeftCorner<2, 2>() = a.rotation();
  return j;
}

Eigen::Matrix3d between_jacobian_a(const Pose2& a, const Pose2& b) {
  const Eigen::Matrix2d rt = a.rotation().transpose();
  const Eigen::Vector2d d = b.translation() - a.translation();
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  j.topLeftCorner<2, 2>() = -rt;
  // d(R^T d)/dtheta_a = [[-s, c], [-c, -s]] d
  const double c = std::cos(a.theta()), s = std::sin(a.theta());
  j(0, 2) = -s * d.x() + c * d.y();
  j(1, 2) = -c * d.x() - s * d.y();
  j(2, 2) = -1.0;
  return j;
}

Eigen::Matrix3d between_jacobian_b(const Pose2& a, const Pose2&) {
  Eigen::Matrix3d j = Eigen::Matrix3d::Identity();
  j.topLeftCorner<2, 2>() = a.rotation().transpose();
  return j;
}

Eigen::Matrix3d rotate_covariance(const Eigen::Matrix3d& covariance, const Eigen::Matrix2d& R) {
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  J.topLeftCorner<2, 2>() = R;
  return J * covariance * J.transpose();
}

}  // namespace traverse
