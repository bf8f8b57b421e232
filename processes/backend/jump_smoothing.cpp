#include "jump_smoothing.hpp"

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

// A step as a body-frame displacement: (x [m], y [m], theta [rad]).
Eigen::Vector3d displacement(const StampedPose& a, const StampedPose& b) {
  const Pose2 step = between(a.T_world_base, b.T_world_base);
  return {step.x(), step.y(), step.theta()};
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
  check.require(c.input == "auto" || c.input == "stream" || c.input == "sparse", "input",
                "must be auto, stream or sparse");
  check.positive("sparse_interval_us", c.sparse_interval_us);
  check.not_negative("min_stream_interval_us", c.min_stream_interval_us);
  check.require(c.min_stream_interval_us < c.sparse_interval_us, "min_stream_interval_us",
                "must be below sparse_interval_us");
  return check.problem();
}

SmoothedTrajectory smooth_jumps(std::vector<StampedPose> poses, const JumpSmoothingConfig& config) {
  SmoothedTrajectory out;
  if (poses.empty()) return out;
  out.poses.push_back(poses.front());
  // Displacements and durations of the preceding (accepted) steps. Their mean velocity is the
  // summed displacement over the summed time, so a step stamped a microsecond after the one
  // before (a log whose times carry little time) does not dominate it.
  std::deque<std::pair<Eigen::Vector3d, double>> recent;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double sum_s = 0.0;
  for (std::size_t k = 1; k < poses.size(); ++k) {
    const bool judged = static_cast<int>(recent.size()) == config.window;
    const Eigen::Vector3d mean = judged ? Eigen::Vector3d(sum / sum_s) : Eigen::Vector3d::Zero();
    // An outlier: pose k lies off the path from k - 1 to k + 1 by more than the minimum and
    // more than half that path's length (or turn), so it is not a curve of it, while that path
    // itself moves as the preceding steps did (else pose k + 1 shares a jump).
    if (judged && k + 1 < poses.size()) {
      const double s = seconds(poses[k - 1], poses[k]) / seconds(poses[k - 1], poses[k + 1]);
      const Pose2 on_path = interpolate(poses[k - 1].T_world_base, poses[k + 1].T_world_base, s);
      const Pose2 off = between(on_path, poses[k].T_world_base);
      const Pose2 path = between(poses[k - 1].T_world_base, poses[k + 1].T_world_base);
      const bool off_path =
          off.translation().norm() > std::max(config.min_jump_m, 0.5 * path.translation().norm()) ||
          std::abs(off.theta()) > std::max(config.min_jump_rad, 0.5 * std::abs(path.theta()));
      const double dt2 = seconds(poses[k - 1], poses[k + 1]);
      if (off_path && !is_jump(displacement(poses[k - 1], poses[k + 1]) / dt2, dt2, mean, config)) {
        poses[k].T_world_base = on_path;
        out.outliers.push_back(static_cast<int>(k));
      }
    }
    const double dt = seconds(poses[k - 1], poses[k]);
    Eigen::Vector3d d = displacement(poses[k - 1], poses[k]);
    // Only judge once the window is full: the average must describe the recent motion.
    if (judged && is_jump(d / dt, dt, mean, config)) {
      d = mean * dt;
      out.replaced_steps.push_back(static_cast<int>(k));
    }
    recent.emplace_back(d, dt);
    sum += d;
    sum_s += dt;
    if (static_cast<int>(recent.size()) > config.window) {
      sum -= recent.front().first;
      sum_s -= recent.front().second;
      recent.pop_front();
    }
    // Carry the rest of the trajectory along: compose the (possibly replaced) step.
    out.poses.push_back(
        {poses[k].utime, out.poses.back().T_world_base * Pose2(d.x(), d.y(), d.z())});
  }
  return out;
}

void JumpSmoother::restart(const StampedPose& raw, const Pose2& smoothed) {
  tail_.assign(1, {raw.utime, smoothed});
  last_raw_ = raw;
}

bool JumpSmoother::is_outlier(const StampedPose& held, const StampedPose& next) const {
  if (tail_.empty()) return false;
  // The two raw steps appended to the smoothed tail, as add() would append them.
  std::vector<StampedPose> window = tail_;
  const Pose2& T = tail_.back().T_world_base;
  window.push_back({held.utime, T * between(last_raw_.T_world_base, held.T_world_base)});
  window.push_back({next.utime, T * between(last_raw_.T_world_base, next.T_world_base)});
  const SmoothedTrajectory s = smooth_jumps(std::move(window), config_);
  return !s.outliers.empty() && s.outliers.back() == static_cast<int>(tail_.size());
}

Pose2 JumpSmoother::replace_outlier(const StampedPose& held, const StampedPose& next) const {
  const double span = static_cast<double>(std::max<int64_t>(1, next.utime - last_raw_.utime));
  const double s = std::clamp(static_cast<double>(held.utime - last_raw_.utime) / span, 0.0, 1.0);
  return interpolate(last_raw_.T_world_base, next.T_world_base, s);
}

Pose2 JumpSmoother::add(const StampedPose& raw, bool& jump) {
  jump = false;
  if (tail_.empty()) {
    restart(raw, raw.T_world_base);
    return raw.T_world_base;
  }
  // The newest raw step is judged against the preceding (already smoothed) steps.
  std::vector<StampedPose> window = tail_;
  window.push_back(
      {raw.utime, tail_.back().T_world_base * between(last_raw_.T_world_base, raw.T_world_base)});
  const SmoothedTrajectory s = smooth_jumps(window, config_);
  const int n = static_cast<int>(s.poses.size());
  jump = !s.replaced_steps.empty() && s.replaced_steps.back() == n - 1;
  const Pose2 smoothed =
      tail_.back().T_world_base * between(s.poses[n - 2].T_world_base, s.poses[n - 1].T_world_base);
  last_raw_ = raw;
  tail_.push_back({raw.utime, smoothed});
  if (static_cast<int>(tail_.size()) > config_.window + 1) tail_.erase(tail_.begin());
  return smoothed;
}

}  // namespace traverse::backend
