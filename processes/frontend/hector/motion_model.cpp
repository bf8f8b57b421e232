#include "motion_model.hpp"

#include <algorithm>

namespace traverse::frontend {
namespace {

// IMU silent for longer than this: rotation comes from the poses' angular velocity instead.
constexpr int64_t kImuStaleUs = 500'000;
// Velocity estimates closer than this in time are averaged (exponentially) to tame the noise of
// differencing poses a few milliseconds apart.
constexpr double kVelocitySmoothingS = 0.1;
// Weight of the newest step in the average step of sparse scans.
constexpr double kSparseStepSmoothing = 0.3;
// Odometry samples older than this (before the newest) are dropped.
constexpr int64_t kOdometryKeepUs = 10'000'000;

// T_odom_base at t, geodesically between the samples around it (`samples` covers t).
Pose2 odometry_at(const std::deque<OdometrySample>& samples, int64_t t) {
  const auto it = std::lower_bound(samples.begin(), samples.end(), t,
                                   [](const OdometrySample& s, int64_t u) { return s.utime < u; });
  if (it->utime == t || it == samples.begin()) return it->T_odom_base;
  const OdometrySample& a = *(it - 1);
  return interpolate(a.T_odom_base, it->T_odom_base,
                     static_cast<double>(t - a.utime) / static_cast<double>(it->utime - a.utime));
}

}  // namespace

MotionModel::MotionModel(const Pose2& T_map_base_initial, const Eigen::Matrix3d& R_base_imu)
    : yaw_(R_base_imu) {
  state_.T_map_base_last = T_map_base_initial;
}

bool MotionModel::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  return angular_velocity_imu.allFinite() && yaw_.add(utime, angular_velocity_imu);
}

bool MotionModel::add_odometry(const OdometrySample& o) {
  if (!(o.T_odom_base.vector().allFinite() && o.velocity.allFinite())) return false;
  if (!odometry_.empty() && o.utime <= odometry_.back().utime) return false;
  odometry_.push_back(o);
  while (odometry_.size() > 2 && odometry_.back().utime - odometry_[1].utime > kOdometryKeepUs) {
    odometry_.pop_front();
  }
  return true;
}

void MotionModel::add_pose(int64_t utime, const Pose2& T_map_base,
                           const Eigen::Matrix3d& covariance, bool sparse) {
  State& s = state_;
  if (s.initialised) {
    const double dt = 1e-6 * static_cast<double>(utime - s.last_utime);
    const Eigen::Vector3d v = between(s.T_map_base_last, T_map_base).log() / dt;
    const double alpha = std::min(1.0, dt / kVelocitySmoothingS);
    s.velocity = alpha * v + (1.0 - alpha) * s.velocity;
    s.last_interval_us = utime - s.last_utime;
    if (sparse) {
      const Eigen::Vector3d step = between(s.T_map_base_last, T_map_base).log();
      constexpr double a = kSparseStepSmoothing;
      s.sparse_step = s.sparse_step ? Eigen::Vector3d(a * step + (1.0 - a) * *s.sparse_step) : step;
    }
    s.recent_intervals_us.add(static_cast<double>(utime - s.last_utime));
  }
  s.T_map_base_last = T_map_base;
  s.last_utime = utime;
  s.covariance_last = covariance;
  s.initialised = true;
}

void MotionModel::add_prediction(int64_t utime, const Pose2& T_map_base,
                                 const Eigen::Matrix3d& covariance, bool sparse) {
  const Eigen::Vector3d velocity = state_.velocity;
  add_pose(utime, T_map_base, covariance, sparse);
  state_.velocity = velocity;  // a prediction carries no new information about the motion
}

bool MotionModel::imu_covers(int64_t from, int64_t to) const {
  return !yaw_.empty() && yaw_.first_utime() <= from && yaw_.last_utime() + kImuStaleUs >= to;
}

bool MotionModel::subsampled_by_travel(int64_t gap_us) const {
  return state_.recent_intervals_us.size() == 5 &&
         state_.recent_intervals_us.percentile(50) > static_cast<double>(gap_us);
}

std::optional<Pose2> MotionModel::odometry_motion(int64_t t0, int64_t t1) const {
  if (odometry_.empty() || odometry_.front().utime > std::min(t0, t1) ||
      odometry_.back().utime < std::max(t0, t1)) {
    return std::nullopt;
  }
  return between(odometry_at(odometry_, t0), odometry_at(odometry_, t1));
}

Pose2 MotionModel::extrapolate(int64_t utime, bool use_imu, bool sparse) const {
  const State& s = state_;
  if (const auto step = odometry_motion(s.last_utime, utime); step && s.initialised) {
    const double turn = use_imu ? yaw_.heading_change(s.last_utime, utime) : step->theta();
    return s.T_map_base_last * Pose2(step->x(), step->y(), turn);
  }
  if (sparse && s.sparse_step && !use_imu) return s.T_map_base_last * Pose2::exp(*s.sparse_step);
  const int64_t horizon = std::min(utime - s.last_utime, 2 * s.last_interval_us);
  Eigen::Vector3d xi = s.velocity * (1e-6 * static_cast<double>(horizon));
  if (use_imu) xi.z() = yaw_.heading_change(s.last_utime, utime);
  return s.T_map_base_last * Pose2::exp(xi);
}

}  // namespace traverse::frontend
