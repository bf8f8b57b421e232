#include "trajectory_prep.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

#include "config.hpp"

namespace traverse::backend {
namespace {

// Time from a to b [s]; equal times count as 1 us.
double seconds(const StampedPose& a, const StampedPose& b) {
  return 1e-6 * static_cast<double>(std::max<int64_t>(b.utime - a.utime, 1));
}

// A step as a body-frame velocity: (vx [m/s], vy [m/s], omega [rad/s]).
Eigen::Vector3d velocity(const StampedPose& a, const StampedPose& b) {
  const Pose2 step = between(a.T_world_base, b.T_world_base);
  return Eigen::Vector3d(step.x(), step.y(), step.theta()) / seconds(a, b);
}

// Whether velocity v over dt [s] is a jump against the mean velocity of the preceding steps.
bool is_jump(const Eigen::Vector3d& v, double dt, const Eigen::Vector3d& mean,
             const JumpSmoothingConfig& c) {
  const Eigen::Vector3d deviation = (v - mean) * dt;
  if (deviation.head<2>().norm() <= c.min_jump_m && std::abs(deviation.z()) <= c.min_jump_rad) {
    return false;
  }
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

std::optional<std::string> validate(const JumpSmoothingConfig& c) {
  ConfigCheck check;
  check.in_range("window", c.window, 1, 1000);
  check.positive("speed_ratio", c.speed_ratio);
  check.not_negative("min_jump_speed_mps", c.min_jump_speed_mps);
  check.positive("max_direction_change_rad", c.max_direction_change_rad);
  check.not_negative("min_moving_speed_mps", c.min_moving_speed_mps);
  check.positive("max_turn_rate_radps", c.max_turn_rate_radps);
  check.not_negative("min_jump_m", c.min_jump_m);
  check.not_negative("min_jump_rad", c.min_jump_rad);
  return check.problem();
}

std::optional<std::string> validate(const KeyPoseConfig& c) {
  ConfigCheck check;
  check.positive("interval_us", c.interval_us);
  check.not_negative("distance_m", c.distance_m);
  check.not_negative("angle_rad", c.angle_rad);
  return check.problem();
}

SmoothedTrajectory smooth_jumps(std::vector<StampedPose> poses, const JumpSmoothingConfig& config) {
  SmoothedTrajectory out;
  if (poses.empty()) return out;
  out.poses.push_back(poses.front());
  std::deque<Eigen::Vector3d> recent;  // velocities of the preceding (accepted) steps
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < poses.size(); ++k) {
    // An outlier: pose k lies off the path from k - 1 to k + 1 by more than the minimum and
    // more than half that path's length (or turn), so it is not a curve of it, while that path
    // itself moves as the preceding steps did (else pose k + 1 shares a jump).
    const bool judged = static_cast<int>(recent.size()) == config.window;
    if (judged && k + 1 < poses.size()) {
      const Eigen::Vector3d mean = sum / static_cast<double>(recent.size());
      const double s = seconds(poses[k - 1], poses[k]) / seconds(poses[k - 1], poses[k + 1]);
      const Pose2 on_path = interpolate(poses[k - 1].T_world_base, poses[k + 1].T_world_base, s);
      const Pose2 off = between(on_path, poses[k].T_world_base);
      const Pose2 path = between(poses[k - 1].T_world_base, poses[k + 1].T_world_base);
      const bool off_path =
          off.translation().norm() > std::max(config.min_jump_m, 0.5 * path.translation().norm()) ||
          std::abs(off.theta()) > std::max(config.min_jump_rad, 0.5 * std::abs(path.theta()));
      if (off_path && !is_jump(velocity(poses[k - 1], poses[k + 1]),
                               seconds(poses[k - 1], poses[k + 1]), mean, config)) {
        poses[k].T_world_base = on_path;
        out.outliers.push_back(static_cast<int>(k));
      }
    }
    Eigen::Vector3d v = velocity(poses[k - 1], poses[k]);
    // Only judge once the window is full: the average must describe the recent motion.
    if (judged) {
      const Eigen::Vector3d mean = sum / static_cast<double>(recent.size());
      if (is_jump(v, seconds(poses[k - 1], poses[k]), mean, config)) {
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
    const double dt = seconds(poses[k - 1], poses[k]);
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
