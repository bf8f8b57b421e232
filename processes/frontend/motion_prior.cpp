#include "motion_prior.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::frontend {
namespace {

// Odometry samples older than this (before the newest) are dropped.
constexpr int64_t kKeepUs = 10'000'000;

}  // namespace

MotionPrior::MotionPrior(const MotionPriorConfig& config) : config_(config) {}

bool MotionPrior::uses_imu() const { return config_.source == "imu" || config_.source == "both"; }

bool MotionPrior::uses_odometry() const {
  return config_.source == "odometry" || config_.source == "both";
}

bool MotionPrior::add_odometry(const OdometrySample& o) {
  if (!(o.T_odom_base.vector().allFinite() && o.pose_covariance.allFinite())) return false;
  if (!samples_.empty() && o.utime <= samples_.back().utime) return false;
  samples_.push_back(o);
  while (samples_.size() > 2 && samples_.back().utime - samples_[1].utime > kKeepUs) {
    samples_.pop_front();
  }
  return true;
}

std::optional<MotionPrior::At> MotionPrior::at(int64_t t, OdometryMiss* miss) const {
  const auto fail = [&](OdometryMiss why) -> std::optional<At> {
    if (miss) *miss = why;
    return std::nullopt;
  };
  if (samples_.empty() || samples_.front().utime > t) return fail(OdometryMiss::kMissing);
  const OdometrySample& last = samples_.back();
  if (t >= last.utime) {
    if (t == last.utime) return At{last.T_odom_base, last.pose_covariance};
    if (t - last.utime > config_.odometry_max_extrapolation_us) return fail(OdometryMiss::kStale);
    // The newest rate carried on: the increment to the newest sample from the latest one at least
    // as far before it as t is after it, scaled to the time past the newest sample. Never the last
    // increment alone: a logger that stamps on arrival bunches samples a millisecond apart, and
    // one such increment carried 90 ms on is a step of metres (intel: 2.2 m, the frontend lost).
    std::size_t i = samples_.size() - 1;
    while (i > 0 && last.utime - samples_[i].utime < t - last.utime) {
      if (samples_[i].utime - samples_[i - 1].utime > config_.odometry_max_gap_us)
        return fail(OdometryMiss::kGap);
      --i;
    }
    if (i == samples_.size() - 1 || last.utime - samples_[i].utime < t - last.utime)
      return fail(OdometryMiss::kStale);
    const OdometrySample& prev = samples_[i];
    const double s =
        static_cast<double>(t - last.utime) / static_cast<double>(last.utime - prev.utime);
    const Pose2 step = Pose2::exp(s * between(prev.T_odom_base, last.T_odom_base).log());
    return At{last.T_odom_base * step, last.pose_covariance, true};
  }
  const auto it = std::lower_bound(samples_.begin(), samples_.end(), t,
                                   [](const OdometrySample& o, int64_t u) { return o.utime < u; });
  if (it->utime == t) return At{it->T_odom_base, it->pose_covariance};
  const OdometrySample& a = *(it - 1);
  if (it->utime - a.utime > config_.odometry_max_gap_us) return fail(OdometryMiss::kGap);
  const double s = static_cast<double>(t - a.utime) / static_cast<double>(it->utime - a.utime);
  return At{interpolate(a.T_odom_base, it->T_odom_base, s),
            (1.0 - s) * a.pose_covariance + s * it->pose_covariance};
}

std::optional<OdometryStep> MotionPrior::odometry_step(int64_t t0, int64_t t1,
                                                       OdometryMiss* miss) const {
  if (miss) *miss = OdometryMiss::kNone;
  if (!uses_odometry()) return std::nullopt;
  const auto a = at(t0, miss);
  if (!a) return std::nullopt;
  const auto b = at(t1, miss);
  if (!b) return std::nullopt;
  OdometryStep step;
  step.T_base0_base1 = between(a->T_odom_base, b->T_odom_base);
  step.extrapolated = b->extrapolated;
  // The messages' covariance grows along the path in the odometry frame: its growth over the
  // step, turned into the base frame at t0 (negative parts, a source resetting it, are dropped).
  Eigen::Matrix3d growth = rotate_covariance(b->covariance - a->covariance,
                                             Pose2(0.0, 0.0, -a->T_odom_base.theta()).rotation());
  for (int i = 0; i < 3; ++i) growth(i, i) = std::max(0.0, growth(i, i));
  const double d = step.T_base0_base1.translation().norm();
  const double turn = std::abs(step.T_base0_base1.theta());
  const double sxy = config_.odometry_sigma_xy_m + config_.odometry_sigma_xy_per_m * d;
  const double sth = config_.odometry_sigma_theta_rad + config_.odometry_sigma_theta_per_m * d +
                     config_.odometry_sigma_theta_per_rad * turn;
  step.covariance = growth.diagonal().asDiagonal();
  step.covariance += Eigen::Vector3d(sxy * sxy, sxy * sxy, sth * sth).asDiagonal().toDenseMatrix();
  if (step.extrapolated) {  // the rate may have changed since the newest sample: double the sigmas
    step.covariance *= 4.0;
  }
  return step;
}

double MotionPrior::linear_window_m(const Eigen::Matrix3d& c, double max_m) const {
  const double sigma = std::sqrt(std::max(c(0, 0), c(1, 1)));
  return std::clamp(config_.search_sigmas * sigma, std::min(config_.search_min_linear_m, max_m),
                    max_m);
}

double MotionPrior::angular_window_rad(const Eigen::Matrix3d& c, double max_rad) const {
  return std::clamp(config_.search_sigmas * std::sqrt(c(2, 2)),
                    std::min(config_.search_min_angular_rad, max_rad), max_rad);
}

}  // namespace traverse::frontend
