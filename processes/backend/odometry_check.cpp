#include "odometry_check.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "config.hpp"

namespace traverse::backend {

std::optional<std::string> validate(const OdometryCheckConfig& c) {
  ConfigCheck check;
  check.positive("min_sigma_xy_m", c.min_sigma_xy_m);
  check.not_negative("sigma_xy_per_m", c.sigma_xy_per_m);
  check.positive("min_sigma_theta_rad", c.min_sigma_theta_rad);
  check.not_negative("sigma_theta_per_m", c.sigma_theta_per_m);
  check.not_negative("sigma_theta_per_rad", c.sigma_theta_per_rad);
  check.positive("max_frontend_chi2", c.max_frontend_chi2);
  check.positive("max_reading_gap_us", c.max_reading_gap_us);
  check.positive("keep_us", c.keep_us);
  check.positive("max_speed_mps", c.max_speed_mps);
  check.positive("max_turn_rate_radps", c.max_turn_rate_radps);
  return check.problem();
}

double step_chi2(const Pose2& a, const Pose2& b, const Eigen::Matrix3d& S) {
  const Eigen::Vector3d e(a.x() - b.x(), a.y() - b.y(), wrap_angle(a.theta() - b.theta()));
  return e.dot(S.ldlt().solve(e));
}

bool scans_side_with_odometry(const OdometryStep& odometry, const Pose2& frontend_motion,
                              const Eigen::Matrix3d& frontend_covariance, const Pose2& match,
                              const Eigen::Matrix3d& match_covariance, double match_raw_response,
                              double frontend_match_raw_response, double gate_chi2) {
  if (!(match_raw_response > frontend_match_raw_response)) return false;
  const double to_odometry =
      step_chi2(match, odometry.motion, odometry.covariance + match_covariance);
  const double to_frontend =
      step_chi2(match, frontend_motion, frontend_covariance + match_covariance);
  return to_odometry <= gate_chi2 && !(to_frontend <= gate_chi2);
}

void OdometryCheck::add(int64_t utime, const Pose2& T_odom_base) {
  if (!config_.enabled) return;
  if (!readings_.empty() && utime <= readings_.back().first) {
    ++counters_.readings_out_of_order;
    return;
  }
  ++counters_.readings;
  if (!readings_.empty()) {
    const double dt = 1e-6 * static_cast<double>(utime - readings_.back().first);
    const Pose2 step = between(readings_.back().second, T_odom_base);
    if (step.translation().norm() > config_.max_speed_mps * dt ||
        std::abs(step.theta()) > config_.max_turn_rate_radps * dt) {
      ++counters_.readings_implausible;
      implausible_.push_back(utime);
    }
  }
  readings_.emplace_back(utime, T_odom_base);
  while (readings_.front().first < utime - config_.keep_us) readings_.pop_front();
  while (!implausible_.empty() && implausible_.front() < utime - config_.keep_us)
    implausible_.pop_front();
}

std::optional<Pose2> OdometryCheck::at(int64_t utime) const {
  const auto later =
      std::lower_bound(readings_.begin(), readings_.end(), utime,
                       [](const std::pair<int64_t, Pose2>& r, int64_t t) { return r.first < t; });
  const int64_t gap = config_.max_reading_gap_us;
  if (later != readings_.end() && later->first == utime) return later->second;
  if (later == readings_.begin()) {
    if (later != readings_.end() && later->first - utime <= gap) return later->second;
    return std::nullopt;
  }
  const auto earlier = std::prev(later);
  if (later == readings_.end()) {
    if (utime - earlier->first <= gap) return earlier->second;
    return std::nullopt;
  }
  if (later->first - earlier->first > 2 * gap) return std::nullopt;
  const double s = static_cast<double>(utime - earlier->first) /
                   static_cast<double>(later->first - earlier->first);
  return interpolate(earlier->second, later->second, s);
}

std::optional<OdometryStep> OdometryCheck::check(int64_t a_utime, int64_t b_utime,
                                                 const Pose2& frontend_motion,
                                                 const Eigen::Matrix3d& frontend_covariance) {
  if (!config_.enabled) return std::nullopt;
  const std::optional<Pose2> a = at(a_utime), b = at(b_utime);
  if (!a || !b) return std::nullopt;
  if (implausible_near(a_utime, b_utime)) {
    ++counters_.steps_implausible;
    return std::nullopt;
  }
  ++counters_.steps_checked;
  OdometryStep step = judge(*a, *b, frontend_motion, frontend_covariance);
  if (step.frontend_rejected) ++counters_.steps_contradicted;
  return step;
}

std::optional<OdometryStep> OdometryCheck::compare(int64_t a_utime, int64_t b_utime,
                                                   const Pose2& frontend_motion,
                                                   const Eigen::Matrix3d& frontend_covariance) const {
  if (!config_.enabled) return std::nullopt;
  const std::optional<Pose2> a = at(a_utime), b = at(b_utime);
  if (!a || !b || implausible_near(a_utime, b_utime)) return std::nullopt;
  return judge(*a, *b, frontend_motion, frontend_covariance);
}

OdometryStep OdometryCheck::judge(const Pose2& a, const Pose2& b, const Pose2& frontend_motion,
                                  const Eigen::Matrix3d& frontend_covariance) const {
  OdometryStep step;
  step.motion = between(a, b);
  const double d = step.motion.translation().norm();
  const double sxy = config_.min_sigma_xy_m + config_.sigma_xy_per_m * d;
  const double sth = config_.min_sigma_theta_rad + config_.sigma_theta_per_m * d +
                     config_.sigma_theta_per_rad * std::abs(step.motion.theta());
  step.covariance = Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal();
  step.frontend_chi2 =
      step_chi2(frontend_motion, step.motion, step.covariance + frontend_covariance);
  step.frontend_rejected = !(step.frontend_chi2 <= config_.max_frontend_chi2);
  return step;
}

bool OdometryCheck::implausible_near(int64_t a_utime, int64_t b_utime) const {
  const auto near = std::lower_bound(implausible_.begin(), implausible_.end(),
                                     a_utime - config_.max_reading_gap_us);
  return near != implausible_.end() && *near <= b_utime + config_.max_reading_gap_us;
}

}  // namespace traverse::backend
