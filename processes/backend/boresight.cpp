#include "boresight.hpp"

#include <cmath>

#include "config.hpp"

namespace traverse::backend {

std::optional<std::string> validate(const BoresightConfig& c) {
  ConfigCheck check;
  check.in_range("min_sigmas", c.min_sigmas, 0.0, 100.0);
  if (check.problem()) return check.problem();
  return validate(static_cast<const calibration::ExtrinsicYawConfig&>(c));
}

void Boresight::update(const std::vector<Pose2>& key_poses) {
  if (!config_.enabled) return;
  estimator_.reset();
  for (const Pose2& T : key_poses) estimator_.add_pose(T);
  yaw_ = estimator_.yaw_rad();
  sigma_ = yaw_ ? estimator_.yaw_sigma_rad() : 0.0;
  if (yaw_ && std::abs(*yaw_) < config_.min_sigmas * sigma_) {
    yaw_.reset();
    sigma_ = 0.0;
  }
}

Pose2 Boresight::published(const Pose2& T_world_base, const Pose2& T_world_first) const {
  if (!yaw_) return T_world_base;
  return calibration::turned_about(T_world_base, T_world_first.translation(), *yaw_);
}

Eigen::Matrix3d Boresight::published(const Eigen::Matrix3d& covariance) const {
  if (!yaw_) return covariance;
  return rotate_covariance(covariance, Pose2(0.0, 0.0, *yaw_).rotation());
}

}  // namespace traverse::backend
