// Heading change of the base from IMU angular rate, for de-skewing scans and predicting rotation.
//
// Seed 000 (section 2) undoes the platform's rotation during a sweep with the IMU: relative
// heading over a few tens of milliseconds is accurate even though absolute heading drifts. Here
// the yaw rate (the IMU rate rotated into the base frame, z component) is integrated with the
// trapezoid rule between samples, so the heading change is available at any time, in particular
// at every point's own time within a sweep.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>

namespace traverse::frontend {

class YawIntegrator {
 public:
  // R_base_imu rotates IMU-frame vectors into the base frame.
  explicit YawIntegrator(const Eigen::Matrix3d& R_base_imu = Eigen::Matrix3d::Identity(),
                         int64_t keep_us = 10'000'000)
      : R_base_imu_(R_base_imu), keep_us_(keep_us) {}

  // Adds one sample (angular velocity [rad/s] in the IMU frame). Samples not after the last one
  // are ignored; returns false for them.
  bool add(int64_t utime, const Eigen::Vector3d& angular_velocity_imu);

  bool empty() const { return samples_.empty(); }
  int64_t first_utime() const { return samples_.front().utime; }
  int64_t last_utime() const { return samples_.back().utime; }
  // True if samples exist at or before t0 and at or after t1.
  bool covers(int64_t t0, int64_t t1) const;

  // Heading change [rad] of the base from t0 to t1 (negative if t1 < t0). Outside the samples the
  // nearest rate is held.
  double heading_change(int64_t t0, int64_t t1) const { return angle_at(t1) - angle_at(t0); }

 private:
  struct Sample {
    int64_t utime;
    double rate;   // [rad/s] base yaw rate
    double angle;  // [rad] integral of the rate from the first kept sample
  };
  double angle_at(int64_t t) const;

  Eigen::Matrix3d R_base_imu_;
  int64_t keep_us_;
  std::deque<Sample> samples_;
};

}  // namespace traverse::frontend
