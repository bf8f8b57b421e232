#include "message_checks.hpp"

#include <cmath>
#include <numbers>

namespace traverse {
namespace {

bool finite(std::initializer_list<double> values) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

template <std::size_t N>
bool finite(const double (&values)[N]) {
  for (double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

std::optional<std::string> implausible(const planar_scan_t& m) {
  if (!finite({m.angle_first, m.angle_step, m.range_min, m.range_max})) {
    return "scan geometry is not finite";
  }
  if (m.n_ranges > 1 && m.angle_step == 0.0f) {
    return "angle_step is 0: every beam points the same way";
  }
  // One sweep of a planar scanner covers at most a turn (a step's rounding beyond it allowed).
  const double span = std::abs(static_cast<double>(m.angle_step)) * std::max(0, m.n_ranges - 1);
  if (span > 2.0 * std::numbers::pi * (1.0 + 1e-3)) {
    return "beams span " + std::to_string(span) + " rad, more than a turn";
  }
  if (m.range_min < 0.0f || !(m.range_max > m.range_min)) {
    return "range_max " + std::to_string(m.range_max) + " m is not above range_min " +
           std::to_string(m.range_min) + " m";
  }
  if (m.utime_last < m.utime_first) return "utime_last is before utime_first";
  if ((m.n_intensities8 != 0 && m.n_intensities8 != m.n_ranges) ||
      (m.n_intensities16 != 0 && m.n_intensities16 != m.n_ranges)) {
    return "intensities do not match the ranges one to one";
  }
  return std::nullopt;
}

std::optional<std::string> implausible(const imu_t& m) {
  if (!finite(m.angular_velocity) || !finite(m.linear_acceleration)) {
    return "IMU sample is not finite";
  }
  return std::nullopt;
}

std::optional<std::string> implausible(const pose2d_t& m) {
  if (!finite({m.x, m.y, m.theta}) || !finite(m.covariance)) return "pose is not finite";
  return std::nullopt;
}

std::optional<std::string> implausible(const odometry_t& m) {
  if (!finite({m.x, m.y, m.theta}) || !finite(m.velocity)) return "odometry is not finite";
  return std::nullopt;
}

}  // namespace traverse
