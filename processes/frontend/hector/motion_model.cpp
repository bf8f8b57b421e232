#include "motion_model.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::frontend {
namespace {

// IMU silent for longer than this: rotation comes from the poses' angular velocity instead.
constexpr int64_t kImuStaleUs = 500'000;
// Velocity estimates closer than this in time are averaged (exponentially) to tame the noise of
// differencing poses a few milliseconds apart.
constexpr double kVelocitySmoothingS = 0.1;
// The poses of the last kRecentPathUs (at most kRecentPathPoses) are held for taken_earlier().
constexpr int64_t kRecentPathUs = 1'000'000;
constexpr std::size_t kRecentPathPoses = 100;
// Weight of the newest step in the average step of sparse scans.
constexpr double kSparseStepSmoothing = 0.3;
}  // namespace

MotionModel::MotionModel(const Pose2& T_map_base_initial, const Eigen::Matrix3d& R_base_imu,
                         const MotionPriorConfig& prior)
    : yaw_(R_base_imu), prior_(prior) {
  state_.T_map_base_last = T_map_base_initial;
}

bool MotionModel::add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  return angular_velocity_imu.allFinite() && yaw_.add(utime, angular_velocity_imu);
}

bool MotionModel::add_odometry(const OdometrySample& o) { return prior_.add_odometry(o); }

void MotionModel::add_pose(int64_t utime, const Pose2& T_map_base,
                           const Eigen::Matrix3d& covariance, bool sparse) {
  State& s = state_;
  if (s.initialised) {
    const int64_t interval_us = utime - s.last_utime;
    const Eigen::Vector3d step = between(s.T_map_base_last, T_map_base).log();
    const double dt = 1e-6 * static_cast<double>(interval_us);
    const Eigen::Vector3d v = step / dt;
    const double alpha = std::min(1.0, dt / kVelocitySmoothingS);
    Eigen::Vector3d velocity = alpha * v + (1.0 - alpha) * s.velocity;
    const double max_change = prior_.config().max_acceleration_mps2 * dt;  // [m/s]
    const Eigen::Vector2d change = velocity.head<2>() - s.velocity.head<2>();
    if (max_change > 0.0 && change.norm() > max_change)
      velocity.head<2>() = s.velocity.head<2>() + change * (max_change / change.norm());
    s.velocity = velocity;
    s.last_interval_us = interval_us;
    if (sparse) {
      constexpr double a = kSparseStepSmoothing;
      s.sparse_step = s.sparse_step ? Eigen::Vector3d(a * step + (1.0 - a) * *s.sparse_step) : step;
    }
    s.recent_intervals_us.add(static_cast<double>(interval_us));
  }
  s.recent_path.emplace_back(utime, T_map_base);
  while (s.recent_path.size() > kRecentPathPoses ||
         s.recent_path.front().first < utime - kRecentPathUs)
    s.recent_path.pop_front();
  s.T_map_base_last = T_map_base;
  s.last_utime = utime;
  s.last_late = false;
  s.covariance_last = covariance;
  s.initialised = true;
}

void MotionModel::add_prediction(int64_t utime, const Pose2& T_map_base,
                                 const Eigen::Matrix3d& covariance, bool sparse, bool late) {
  const Eigen::Vector3d velocity = state_.velocity;
  add_pose(utime, T_map_base, covariance, sparse);
  state_.velocity = velocity;  // a prediction carries no new information about the motion
  state_.last_late = late;
}

bool MotionModel::taken_earlier(const Pose2& T_match, const Pose2& T_predicted, double scale_xy,
                                double scale_theta) const {
  const auto distance = [&](const Pose2& a, const Pose2& b) {
    const Eigen::Vector3d d = between(a, b).log();
    return std::max(d.head<2>().norm() / scale_xy, std::abs(d.z()) / scale_theta);
  };
  const auto& path = state_.recent_path;
  if (state_.last_late || path.size() < 3 || distance(path.back().second, T_match) <= 2.0 / 3.0 ||
      distance(T_predicted, T_match) <= 2.0 / 3.0)
    return false;
  constexpr int kSteps = 10;  // points looked at per segment
  for (std::size_t i = 1; i + 1 < path.size(); ++i) {
    const Pose2& from = path[i - 1].second;
    const Eigen::Vector3d step = between(from, path[i].second).log();
    for (int k = 0; k <= kSteps; ++k) {
      if (distance(from * Pose2::exp(step * (static_cast<double>(k) / kSteps)), T_match) < 1.0 / 3.0)
        return true;
    }
  }
  return false;
}

bool MotionModel::imu_covers(int64_t from, int64_t to) const {
  return prior_.uses_imu() && !yaw_.empty() && yaw_.first_utime() <= from &&
         yaw_.last_utime() + kImuStaleUs >= to;
}

bool MotionModel::subsampled_by_travel(int64_t gap_us) const {
  return pace_known() &&
         state_.recent_intervals_us.percentile(50) > static_cast<double>(gap_us);
}

MotionModel::Prediction MotionModel::predict(int64_t utime, bool use_imu, bool sparse,
                                             bool with_odometry) const {
  const State& s = state_;
  Prediction p;
  if (s.initialised && with_odometry)
    p.odometry = prior_.odometry_step(s.last_utime, utime, &p.odometry_miss);
  if (p.odometry) {
    const Pose2& step = p.odometry->T_base0_base1;
    const double turn = use_imu ? yaw_.heading_change(s.last_utime, utime) : step.theta();
    p.T_map_base = s.T_map_base_last * Pose2(step.x(), step.y(), turn);
    p.covariance =
        s.covariance_last + rotate_covariance(p.odometry->covariance, s.T_map_base_last.rotation());
    return p;
  }
  const double dt = 1e-6 * static_cast<double>(std::max<int64_t>(0, utime - s.last_utime));
  const MotionPriorConfig& c = prior_.config();
  p.covariance = s.covariance_last + Eigen::Vector3d(std::pow(c.prediction_sigma_mps * dt, 2),
                                                     std::pow(c.prediction_sigma_mps * dt, 2),
                                                     std::pow(c.prediction_sigma_radps * dt, 2))
                                         .asDiagonal()
                                         .toDenseMatrix();
  if (sparse && s.sparse_step && !use_imu) {
    p.T_map_base = s.T_map_base_last * Pose2::exp(*s.sparse_step);
    return p;
  }
  const int64_t horizon = std::min(utime - s.last_utime, 2 * s.last_interval_us);
  Eigen::Vector3d xi = s.velocity * (1e-6 * static_cast<double>(horizon));
  if (use_imu) xi.z() = yaw_.heading_change(s.last_utime, utime);
  p.T_map_base = s.T_map_base_last * Pose2::exp(xi);
  return p;
}

}  // namespace traverse::frontend
