#include "deskew.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace traverse::frontend {

void deskew_points(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
                   int64_t utime_ref, const std::function<double(int64_t)>& heading_change,
                   const Eigen::Vector2d& velocity_base, bool translation) {
  for (std::size_t i = 0; i < points_base.size(); ++i) {
    if (utimes[i] == utime_ref) continue;
    // T_ref_i: the base at the point's time seen from the base at the reference time. Over a
    // sweep (tens of ms) the translation is well approximated by velocity times time.
    const double dtheta = heading_change(utimes[i]);
    const double c = std::cos(dtheta), s = std::sin(dtheta);
    const Eigen::Vector2d& p = points_base[i];
    Eigen::Vector2d q(c * p.x() - s * p.y(), s * p.x() + c * p.y());
    if (translation) q += velocity_base * (1e-6 * static_cast<double>(utimes[i] - utime_ref));
    points_base[i] = q;
  }
}

void deskew_sweep(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
                  int64_t utime_ref, const MotionModel& motion, bool use_imu, bool translation) {
  // The IMU's integral is evaluated at kKnots times across the sweep and interpolated linearly
  // per point (the integral is smooth: a few samples fall within a sweep), instead of a search
  // in the IMU buffer for each of thousands of points.
  constexpr int kKnots = 33;
  const double omega = motion.velocity().z();
  const int64_t t0 = utimes.empty() ? utime_ref : std::min(utimes.front(), utime_ref);
  const double span = static_cast<double>(std::max<int64_t>(1, utime_ref - t0));
  std::array<double, kKnots> knots{};
  if (use_imu) {
    for (int k = 0; k < kKnots; ++k) {
      knots[k] = motion.imu_heading_change(utime_ref, t0 + std::llround(span * k / (kKnots - 1)));
    }
  }
  auto heading_change = [&](int64_t t) {
    if (!use_imu) return omega * 1e-6 * static_cast<double>(t - utime_ref);
    const double x = std::clamp(static_cast<double>(t - t0) / span, 0.0, 1.0) * (kKnots - 1);
    const int k = std::min(kKnots - 2, static_cast<int>(x));
    return knots[k] + (x - k) * (knots[k + 1] - knots[k]);
  };
  deskew_points(points_base, utimes, utime_ref, heading_change, motion.velocity().head<2>(),
                translation);
}

}  // namespace traverse::frontend
