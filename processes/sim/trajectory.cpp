#include "trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace traverse::sim {

double trapezoid_duration(double amount, double vmax, double a) {
  if (amount <= 0.0) return 0.0;
  if (amount < vmax * vmax / a) return 2.0 * std::sqrt(amount / a);  // never reaches vmax
  return amount / vmax + vmax / a;
}

void trapezoid_at(double amount, double vmax, double a, double tau, double& s, double& v) {
  const double T = trapezoid_duration(amount, vmax, a);
  tau = std::clamp(tau, 0.0, T);
  const double vtop = std::min(vmax, std::sqrt(amount * a));
  const double ta = vtop / a;  // time spent accelerating (and braking)
  if (tau < ta) {
    v = a * tau;
    s = 0.5 * a * tau * tau;
  } else if (tau <= T - ta) {
    v = vtop;
    s = 0.5 * vtop * ta + vtop * (tau - ta);
  } else {
    const double r = T - tau;
    v = a * r;
    s = amount - 0.5 * a * r * r;
  }
}

void Trajectory::add(Kind kind, const Pose2& start, double amount, double vmax, double accel) {
  const double t0 = segments_.empty() ? 0.0 : segments_.back().t1;
  double dur = 0.0;
  double wheel = 0.0;
  if (kind == Kind::kPause) {
    dur = amount;
  } else {
    dur = trapezoid_duration(std::abs(amount), vmax, accel);
    wheel = kind == Kind::kLine ? amount : std::abs(amount) * platform_.half_track_m;
  }
  if (dur <= 0.0) return;
  segments_.push_back({kind, t0, t0 + dur, start, amount, vmax, accel, dist_});
  dist_ += wheel;
}

Trajectory::Trajectory(const RouteSpec& route, const PlatformConfig& platform, Rng& rng)
    : platform_(platform) {
  if (route.waypoints.size() < 2) throw std::runtime_error("route needs at least 2 waypoints");
  if (route.speed_mps <= 0.0 || platform.accel_mps2 <= 0.0 || platform.yaw_rate_radps <= 0.0 ||
      platform.yaw_accel_radps2 <= 0.0)
    throw std::runtime_error("route speed and platform rates must be > 0");
  std::vector<Eigen::Vector2d> wp;
  for (const auto& p : route.waypoints) {
    if (p.size() != 2) throw std::runtime_error("route waypoint needs [x, y]");
    wp.emplace_back(p[0], p[1]);
  }
  for (const auto& vib : platform.vibration) {
    if (vib.axis != "x" && vib.axis != "y" && vib.axis != "yaw")
      throw std::runtime_error("vibration axis must be x, y or yaw, not '" + vib.axis + "'");
    if (vib.wavelength_m <= 0.0) throw std::runtime_error("vibration wavelength must be > 0");
    phases_.push_back(rng.uniform(0.0, 2.0 * std::numbers::pi));
    axes_.push_back(vib.axis == "x" ? 0 : vib.axis == "y" ? 1 : 2);
  }
  auto heading_of = [&](std::size_t i) {
    const Eigen::Vector2d d = wp[i + 1] - wp[i];
    return std::atan2(d.y(), d.x());
  };
  double heading = route.start_heading_rad < 1e8 ? route.start_heading_rad : heading_of(0);
  Pose2 pose(wp[0].x(), wp[0].y(), heading);
  add(Kind::kPause, pose, route.start_pause_s, 0, 0);
  for (std::size_t i = 0; i + 1 < wp.size(); ++i) {
    // Turn on the spot towards the next waypoint, then drive there.
    const double turn = wrap_angle(heading_of(i) - heading);
    add(Kind::kTurn, pose, turn, platform.yaw_rate_radps, platform.yaw_accel_radps2);
    heading = wrap_angle(heading + turn);
    pose = Pose2(wp[i].x(), wp[i].y(), heading);
    const double len = (wp[i + 1] - wp[i]).norm();
    add(Kind::kLine, pose, len, route.speed_mps, platform.accel_mps2);
    length_m_ += len;
    pose = Pose2(wp[i + 1].x(), wp[i + 1].y(), heading);
    if (std::find(route.stop_at.begin(), route.stop_at.end(), static_cast<int>(i + 1)) !=
        route.stop_at.end())
      add(Kind::kPause, pose, route.stop_s, 0, 0);
  }
  add(Kind::kPause, pose, route.end_pause_s, 0, 0);
  if (segments_.empty()) throw std::runtime_error("route has no motion");
}

Trajectory::State Trajectory::nominal_state(double t) const {
  t = std::clamp(t, 0.0, duration_s());
  // Segments are sorted by time; find the one containing t.
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                             [](double x, const Segment& s) { return x < s.t1; });
  if (it == segments_.end()) --it;
  const Segment& s = *it;
  const double tau = t - s.t0;
  switch (s.kind) {
    case Kind::kPause:
      return {s.start, s.dist0, 0.0};
    case Kind::kLine: {
      double d, v;
      trapezoid_at(s.amount, s.vmax, s.accel, tau, d, v);
      const Pose2 p = s.start * Pose2(d, 0.0, 0.0);
      return {p, s.dist0 + d, v};
    }
    case Kind::kTurn:
    default: {
      double a, w;
      trapezoid_at(std::abs(s.amount), s.vmax, s.accel, tau, a, w);
      const double sign = s.amount < 0 ? -1.0 : 1.0;
      const Pose2 p(s.start.x(), s.start.y(), wrap_angle(s.start.theta() + sign * a));
      return {p, s.dist0 + a * platform_.half_track_m, w * platform_.half_track_m};
    }
  }
}

Pose2 Trajectory::nominal_pose(double t) const { return nominal_state(t).pose; }

Pose2 Trajectory::pose(double t) const {
  const State st = nominal_state(t);
  const double gain = std::min(1.0, st.wheel_speed / platform_.vibration_ref_speed_mps);
  if (gain <= 0.0) return st.pose;
  double offset[3] = {0.0, 0.0, 0.0};  // x [m], y [m], yaw [rad] in the base frame
  for (std::size_t k = 0; k < platform_.vibration.size(); ++k) {
    const auto& vib = platform_.vibration[k];
    offset[axes_[k]] += gain * vib.amplitude *
                        std::sin(2.0 * std::numbers::pi * st.dist / vib.wavelength_m + phases_[k]);
  }
  return st.pose * Pose2(offset[0], offset[1], offset[2]);
}

}  // namespace traverse::sim
