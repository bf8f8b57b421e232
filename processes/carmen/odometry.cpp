#include "odometry.hpp"

#include <cmath>

#include "config.hpp"

namespace traverse::carmen {

std::optional<std::string> validate(const OdometryNoise& n) {
  ConfigCheck check;
  check.not_negative("forward_m_per_sqrt_m", n.forward_m_per_sqrt_m);
  check.not_negative("lateral_m_per_sqrt_m", n.lateral_m_per_sqrt_m);
  check.not_negative("heading_rad_per_sqrt_rad", n.heading_rad_per_sqrt_rad);
  check.not_negative("heading_rad_per_sqrt_m", n.heading_rad_per_sqrt_m);
  check.positive("velocity_forward_mps", n.velocity_forward_mps);
  check.positive("velocity_lateral_mps", n.velocity_lateral_mps);
  check.positive("velocity_turn_radps", n.velocity_turn_radps);
  return check.problem();
}

void OdometryChain::add(const Pose2& T_log_base) {
  if (!started_) {
    started_ = true;
    T_odom_base_ = T_log_base;
    T_log_previous_ = T_log_base;
    return;
  }
  const Pose2 step = between(T_log_previous_, T_log_base);
  T_log_previous_ = T_log_base;
  const double d = step.translation().norm();
  const Eigen::Vector3d q(
      noise_.forward_m_per_sqrt_m * noise_.forward_m_per_sqrt_m * d,
      noise_.lateral_m_per_sqrt_m * noise_.lateral_m_per_sqrt_m * d,
      noise_.heading_rad_per_sqrt_rad * noise_.heading_rad_per_sqrt_rad * std::abs(step.theta()) +
          noise_.heading_rad_per_sqrt_m * noise_.heading_rad_per_sqrt_m * d);
  const Eigen::Matrix3d Ja = compose_jacobian_a(T_odom_base_, step);
  const Eigen::Matrix3d Jb = compose_jacobian_b(T_odom_base_, step);
  covariance_ = Ja * covariance_ * Ja.transpose() + Jb * q.asDiagonal() * Jb.transpose();
  T_odom_base_ = T_odom_base_ * step;
  travel_m_ += d;
}

void OdometryChain::reanchor(const Pose2& T_log_base) {
  if (!started_) {
    add(T_log_base);
    return;
  }
  T_log_previous_ = T_log_base;
}

Eigen::Matrix3d velocity_covariance(const OdometryNoise& n) {
  return Eigen::Vector3d(n.velocity_forward_mps * n.velocity_forward_mps,
                         n.velocity_lateral_mps * n.velocity_lateral_mps,
                         n.velocity_turn_radps * n.velocity_turn_radps)
      .asDiagonal();
}

}  // namespace traverse::carmen
