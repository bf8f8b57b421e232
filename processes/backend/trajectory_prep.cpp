#include "trajectory_prep.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace traverse::backend {
namespace {

// A step as a body-frame velocity: (vx [m/s], vy [m/s], omega [rad/s]).
Eigen::Vector3d velocity(const StampedPose& a, const StampedPose& b) {
  const double dt = 1e-6 * static_cast<double>(std::max<int64_t>(b.utime - a.utime, 1));
  const Pose2 step = between(a.T_world_base, b.T_world_base);
  return Eigen::Vector3d(step.x(), step.y(), step.theta()) / dt;
}

bool is_jump(const Eigen::Vector3d& v, const Eigen::Vector3d& mean, const JumpSmoothingConfig& c) {
  const double speed = v.head<2>().norm(), mean_speed = mean.head<2>().norm();
  if (speed > c.min_jump_speed_mps && speed > c.speed_ratio * mean_speed) return true;
  if (std::abs(v.z()) > c.max_turn_rate_radps) return true;
  if (mean_speed > c.min_moving_speed_mps && speed > c.min_moving_speed_mps) {
    const double cosine = v.head<2>().dot(mean.head<2>()) / (speed * mean_speed);
    if (std::acos(std::clamp(cosine, -1.0, 1.0)) > c.max_direction_change_rad) return true;
  }
  return false;
}

}  // namespace

SmoothedTrajectory smooth_jumps(const std::vector<StampedPose>& poses,
                                const JumpSmoothingConfig& config) {
  SmoothedTrajectory out;
  if (poses.empty()) return out;
  out.poses.push_back(poses.front());
  std::deque<Eigen::Vector3d> recent;  // velocities of the preceding (accepted) steps
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < poses.size(); ++k) {
    Eigen::Vector3d v = velocity(poses[k - 1], poses[k]);
    // Only judge once the window is full: the average must describe the recent motion.
    if (static_cast<int>(recent.size()) == config.window) {
      const Eigen::Vector3d mean = sum / static_cast<double>(recent.size());
      if (is_jump(v, mean, config)) {
        v = mean;
        out.replaced_steps.push_back(static_cast<int>(k));
      }
    }
    recent.push_back(v);
    sum += v;
    if (static_cast<int>(recent.size()) > config.window) {
      sum -= recent.front();
      recent.pop_front();
    }
    // Carry the rest of the trajectory along: compose the (possibly replaced) step.
    const double dt =
        1e-6 * static_cast<double>(std::max<int64_t>(poses[k].utime - poses[k - 1].utime, 1));
    const Pose2 step(v.x() * dt, v.y() * dt, v.z() * dt);
    out.poses.push_back({poses[k].utime, out.poses.back().T_world_base * step});
  }
  return out;
}

std::vector<int> select_key_poses(const std::vector<StampedPose>& poses,
                                  const KeyPoseConfig& config) {
  std::vector<int> keys;
  if (poses.empty()) return keys;
  keys.push_back(0);
  double distance = 0.0, angle = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const Pose2 step = between(poses[k - 1].T_world_base, poses[k].T_world_base);
    distance += step.translation().norm();
    angle += std::abs(step.theta());
    const bool by_time =
        config.interval_us > 0 && poses[k].utime - poses[keys.back()].utime >= config.interval_us;
    const bool by_distance = config.distance_m > 0.0 && distance >= config.distance_m;
    const bool by_angle = config.angle_rad > 0.0 && angle >= config.angle_rad;
    if (by_time || by_distance || by_angle) {
      keys.push_back(static_cast<int>(k));
      distance = angle = 0.0;
    }
  }
  return keys;
}

}  // namespace traverse::backend
