#include "odometry.hpp"

#include <cmath>
#include <numbers>

namespace traverse::sim {

OdometrySim::OdometrySim(const WheelEncoderEffect& effect, double half_track_m,
                         const Trajectory& trajectory, const Clock& clock, Rng rng,
                         const SensorClock& own_clock)
    : effect_(effect),
      half_track_m_(half_track_m),
      half_track_true_(half_track_m),
      trajectory_(trajectory),
      clock_(clock),
      rng_(rng),
      own_clock_(own_clock) {
  for (double& r : radius_)
    r = effect_.wheel_radius_m * (1.0 + rng_.normal(effect_.radius_error_sigma));
  half_track_true_ = half_track_m * (1.0 + rng_.normal(effect_.track_error_sigma));
}

OdometryData OdometrySim::sample(int64_t k) {
  const int64_t true_utime = sample_utime(k);
  const Pose2 now = trajectory_.nominal_pose(clock_.seconds(true_utime));
  const double dt = 1.0 / effect_.rate_hz;
  const double tick_m = 2.0 * std::numbers::pi * effect_.wheel_radius_m / effect_.ticks_per_rev;
  double d_odom[2] = {0.0, 0.0};
  if (started_) {
    // Ground distance of each wheel over the interval (arc of the true motion), then its rotation.
    const Pose2 step = between(last_true_, now);
    const double ds = step.x(), dth = step.theta();
    const double ground[2] = {ds - half_track_true_ * dth, ds + half_track_true_ * dth};
    for (int w = 0; w < 2; ++w) {
      const double slip = rng_.normal(effect_.slip_sigma);
      angle_[w] += ground[w] * (1.0 + slip) / radius_[w];
      const int64_t ticks = static_cast<int64_t>(
          std::floor(angle_[w] / (2.0 * std::numbers::pi) * effect_.ticks_per_rev));
      d_odom[w] = static_cast<double>(ticks - ticks_[w]) * tick_m;
      ticks_[w] = ticks;
    }
  }
  started_ = true;
  last_true_ = now;
  // Differential drive with the nominal radius and track, midpoint heading.
  const double ds = 0.5 * (d_odom[0] + d_odom[1]);
  const double dth = (d_odom[1] - d_odom[0]) / (2.0 * half_track_m_);
  const double mid = state_.theta + 0.5 * dth;
  // Covariance: random slip (slip_sigma of each wheel's distance) and quantisation (tick^2 / 6
  // for the difference of two rounded counts), through the integration's Jacobians.
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  J(0, 2) = -ds * std::sin(mid);
  J(1, 2) = ds * std::cos(mid);
  Eigen::Matrix<double, 3, 2> Jw;
  const double b2 = 2.0 * half_track_m_;
  for (int w = 0; w < 2; ++w) {
    const double sign = w == 0 ? -1.0 : 1.0;
    Jw(0, w) = 0.5 * std::cos(mid) - sign * ds * std::sin(mid) / (2.0 * b2);
    Jw(1, w) = 0.5 * std::sin(mid) + sign * ds * std::cos(mid) / (2.0 * b2);
    Jw(2, w) = sign / b2;
  }
  Eigen::Matrix2d Q = Eigen::Matrix2d::Zero();
  for (int w = 0; w < 2; ++w)
    Q(w, w) = std::pow(effect_.slip_sigma * d_odom[w], 2) + tick_m * tick_m / 6.0;
  cov_ = J * cov_ * J.transpose() + Jw * Q * Jw.transpose();
  state_.x += ds * std::cos(mid);
  state_.y += ds * std::sin(mid);
  state_.theta = wrap_angle(state_.theta + dth);
  state_.forward = ds / dt;
  state_.turn = dth / dt;
  state_.utime = sample_stamp(k);
  state_.ticks_left = ticks_[0];
  state_.ticks_right = ticks_[1];
  for (int i = 0; i < 9; ++i) state_.pose_covariance[i] = cov_(i / 3, i % 3);
  Eigen::Matrix3d vel = Eigen::Matrix3d::Zero();
  vel(0, 0) = 0.25 * (Q(0, 0) + Q(1, 1)) / (dt * dt);
  vel(2, 2) = (Q(0, 0) + Q(1, 1)) / (b2 * b2 * dt * dt);
  vel(0, 2) = vel(2, 0) = 0.5 * (Q(1, 1) - Q(0, 0)) / (b2 * dt * dt);
  for (int i = 0; i < 9; ++i) state_.velocity_covariance[i] = vel(i / 3, i % 3);
  return state_;
}

}  // namespace traverse::sim
