// Wheel encoders on the cart's two rear wheels and the odometry integrated from them, as a
// differential-drive robot's base reports it. Each wheel rolls the cart's true (vibration-free)
// path; its encoder counts ticks of its rotation, which is the ground distance over the wheel's
// true radius plus random slip. The odometry integrates the ticks with the nominal radius and
// track, so a wrong radius or track shows as scale and heading drift, slip as a random walk, and
// the tick size as quantisation. The covariance reported is that of the random part (slip and
// quantisation), propagated through the integration; the systematic radius and track errors are
// not in it (a platform does not know them either).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "clocks.hpp"
#include "effects.hpp"
#include "rng.hpp"
#include "sensors.hpp"
#include "trajectory.hpp"

namespace traverse::sim {

struct OdometryData {
  int64_t utime = 0;                            // [us] stamp (the encoders' clock)
  double x = 0.0, y = 0.0, theta = 0.0;         // [m, m, rad] T_odom_base
  double forward = 0.0, turn = 0.0;             // [m/s], [rad/s] over the last interval
  std::array<double, 9> pose_covariance{};      // (x, y, theta), m^2, m rad, rad^2
  std::array<double, 9> velocity_covariance{};  // (forward, left, turn)
  int64_t ticks_left = 0, ticks_right = 0;      // encoder counts since the start
};

class OdometrySim {
 public:
  OdometrySim(const WheelEncoderEffect& effect, double half_track_m, const Trajectory& trajectory,
              const Clock& clock, Rng rng, const SensorClock& own_clock);

  int64_t sample_utime(int64_t k) const { return clock_.sample_utime(k, effect_.rate_hz); }
  int64_t sample_stamp(int64_t k) const {
    const int64_t u = sample_utime(k);
    return own_clock_.stamp(u, clock_.seconds(u), k);
  }
  // Sample k (in order; the first one asked for starts the odometry frame).
  OdometryData sample(int64_t k);

  // This run's true wheel radii [m] and half track [m] (tests).
  double radius_left() const { return radius_[0]; }
  double radius_right() const { return radius_[1]; }
  double true_half_track() const { return half_track_true_; }

 private:
  WheelEncoderEffect effect_;
  double half_track_m_, half_track_true_;
  const Trajectory& trajectory_;
  Clock clock_;
  Rng rng_;
  SensorClock own_clock_;
  double radius_[2] = {0, 0};
  double angle_[2] = {0, 0};  // [rad] true wheel rotation so far
  int64_t ticks_[2] = {0, 0};
  bool started_ = false;
  Pose2 last_true_;
  OdometryData state_;
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Zero();
};

}  // namespace traverse::sim
