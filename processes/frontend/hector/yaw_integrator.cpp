#include "yaw_integrator.hpp"

#include <algorithm>

namespace traverse::frontend {

bool YawIntegrator::add(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) {
  const double rate = (R_base_imu_ * angular_velocity_imu).z();
  if (!samples_.empty() && utime <= samples_.back().utime) return false;
  double angle = 0.0;
  if (!samples_.empty()) {
    const Sample& last = samples_.back();
    angle = last.angle + 0.5 * (last.rate + rate) * 1e-6 * static_cast<double>(utime - last.utime);
  }
  samples_.push_back({utime, rate, angle});
  while (samples_.size() > 2 && samples_.back().utime - samples_[1].utime > keep_us_) {
    samples_.pop_front();
  }
  return true;
}

bool YawIntegrator::covers(int64_t t0, int64_t t1) const {
  return !samples_.empty() && samples_.front().utime <= t0 && samples_.back().utime >= t1;
}

double YawIntegrator::angle_at(int64_t t) const {
  if (samples_.empty()) return 0.0;
  const Sample& first = samples_.front();
  const Sample& last = samples_.back();
  if (t <= first.utime)
    return first.angle - first.rate * 1e-6 * static_cast<double>(first.utime - t);
  if (t >= last.utime) return last.angle + last.rate * 1e-6 * static_cast<double>(t - last.utime);
  // First sample after t; the rate is linear between it and the one before.
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                             [](int64_t u, const Sample& s) { return u < s.utime; });
  const Sample& b = *it;
  const Sample& a = *(it - 1);
  const double dt = 1e-6 * static_cast<double>(t - a.utime);
  const double span = 1e-6 * static_cast<double>(b.utime - a.utime);
  const double rate_t = a.rate + (b.rate - a.rate) * dt / span;
  return a.angle + 0.5 * (a.rate + rate_t) * dt;
}

}  // namespace traverse::frontend
