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
  segments_.push_back({kind, t0, t0 + dur, start, amount, vmax, accel, dist_, -1});
  dist_ += wheel;
}

std::vector<Waypoint> expand_route(const RouteSpec& route, const std::vector<std::string>& layers) {
  auto point = [](const std::vector<double>& p) {
    if (p.size() != 2) throw std::runtime_error("route waypoint needs [x, y]");
    return Eigen::Vector2d(p[0], p[1]);
  };
  std::vector<Waypoint> out;
  for (std::size_t i = 0; i < route.waypoints.size(); ++i) {
    const bool stop = std::find(route.stop_at.begin(), route.stop_at.end(), static_cast<int>(i)) !=
                      route.stop_at.end();
    out.push_back({point(route.waypoints[i]), stop});
    for (const auto& d : route.detours) {
      if (d.after < 0 || d.after + 1 >= static_cast<int>(route.waypoints.size()))
        throw std::runtime_error("route detour 'after' must name a waypoint before the last");
      if (d.after != static_cast<int>(i) ||
          std::find(layers.begin(), layers.end(), d.layer) == layers.end())
        continue;
      for (const auto& p : d.waypoints) out.push_back({point(p), false});
    }
  }
  return out;
}

double draw_start_yaw(const MotionEffect& motion, Rng rng) {
  if (!motion.enabled) return 0.0;
  const double sign = rng.bernoulli(0.5) ? 1.0 : -1.0;
  return sign * rng.uniform(motion.start_yaw_min_rad, motion.start_yaw_max_rad);
}

Trajectory::Trajectory(const RouteSpec& route, const PlatformConfig& platform, Rng& rng,
                       const Effects& effects, double start_yaw_rad)
    : platform_(platform), start_yaw_rad_(effects.motion.enabled ? start_yaw_rad : 0.0) {
  if (route.waypoints.size() < 2) throw std::runtime_error("route needs at least 2 waypoints");
  if (route.speed_mps <= 0.0 || platform.accel_mps2 <= 0.0 || platform.yaw_rate_radps <= 0.0 ||
      platform.yaw_accel_radps2 <= 0.0)
    throw std::runtime_error("route speed and platform rates must be > 0");
  const std::vector<Waypoint> wp = expand_route(route, effects.world_layers);
  for (const auto& vib : platform.vibration) {
    if (vib.axis != "x" && vib.axis != "y" && vib.axis != "yaw")
      throw std::runtime_error("vibration axis must be x, y or yaw, not '" + vib.axis + "'");
    if (vib.wavelength_m <= 0.0) throw std::runtime_error("vibration wavelength must be > 0");
    phases_.push_back(rng.uniform(0.0, 2.0 * std::numbers::pi));
    axes_.push_back(vib.axis == "x" ? 0 : vib.axis == "y" ? 1 : 2);
  }
  if (effects.motion.enabled)
    plan_pushed(route, wp, effects.motion, rng);
  else
    plan_stop_and_turn(route, wp);
  if (segments_.empty()) throw std::runtime_error("route has no motion");
}

namespace {

// [rad] heading of the leg from waypoint i to i + 1.
double leg_heading(const std::vector<Waypoint>& wp, std::size_t i) {
  const Eigen::Vector2d d = wp[i + 1].p - wp[i].p;
  return std::atan2(d.y(), d.x());
}

}  // namespace

Pose2 Trajectory::start(const RouteSpec& route, const std::vector<Waypoint>& wp, double yaw) {
  const double heading =
      route.start_heading_rad < 1e8 ? route.start_heading_rad : leg_heading(wp, 0);
  const Pose2 pose(wp[0].p.x(), wp[0].p.y(), wrap_angle(heading + yaw));
  add(Kind::kPause, pose, route.start_pause_s, 0, 0);
  return pose;
}

void Trajectory::plan_stop_and_turn(const RouteSpec& route, const std::vector<Waypoint>& wp) {
  auto heading_of = [&](std::size_t i) { return leg_heading(wp, i); };
  Pose2 pose = start(route, wp);
  double heading = pose.theta();
  for (std::size_t i = 0; i + 1 < wp.size(); ++i) {
    // Turn on the spot towards the next waypoint, then drive there.
    const double turn = wrap_angle(heading_of(i) - heading);
    add(Kind::kTurn, pose, turn, platform_.yaw_rate_radps, platform_.yaw_accel_radps2);
    heading = wrap_angle(heading + turn);
    pose = Pose2(wp[i].p.x(), wp[i].p.y(), heading);
    const double len = (wp[i + 1].p - wp[i].p).norm();
    add(Kind::kLine, pose, len, route.speed_mps, platform_.accel_mps2);
    length_m_ += len;
    pose = Pose2(wp[i + 1].p.x(), wp[i + 1].p.y(), heading);
    if (wp[i + 1].stop) add(Kind::kPause, pose, route.stop_s, 0, 0);
  }
  add(Kind::kPause, pose, route.end_pause_s, 0, 0);
}

void Trajectory::add_run(PushedRun run, const Pose2& start) {
  const double t0 = segments_.empty() ? 0.0 : segments_.back().t1;
  segments_.push_back({Kind::kRun, t0, t0 + run.duration_s(), start, run.length_m(), 0, 0, dist_,
                       static_cast<int>(runs_.size())});
  dist_ += run.length_m();
  length_m_ += run.length_m();
  runs_.push_back(std::move(run));
}

void Trajectory::plan_pushed(const RouteSpec& route, const std::vector<Waypoint>& wp,
                             const MotionEffect& motion, Rng& rng) {
  // Runs between stops: a waypoint where the route pauses, or a reversal sharper than
  // spin_turn_min_rad, ends a run; the cart then turns on the spot towards the next leg.
  auto heading_of = [&](std::size_t i) { return leg_heading(wp, i); };
  Pose2 pose = start(route, wp, start_yaw_rad_);
  // Set down along its first leg, the cart rolls back onto the line (the first run's lead-in);
  // set down facing elsewhere, it turns on the spot towards the leg, its yaw included.
  const double set_down_along = wrap_angle(pose.theta() - start_yaw_rad_);
  const bool along_first_leg = std::abs(wrap_angle(set_down_along - heading_of(0))) < 1e-9;
  double lead_in_yaw = along_first_leg ? start_yaw_rad_ : 0.0;
  double heading = along_first_leg ? set_down_along : pose.theta();
  std::size_t first = 0;
  for (std::size_t i = 1; i < wp.size(); ++i) {
    const bool last = i + 1 == wp.size();
    const bool reversal = !last && std::abs(wrap_angle(heading_of(i) - heading_of(i - 1))) >=
                                       motion.spin_turn_min_rad;
    if (!last && !reversal && !wp[i].stop) continue;
    // Turn on the spot towards the run's first leg, then roll through wp[first..i].
    const double turn = wrap_angle(heading_of(first) - heading);
    add(Kind::kTurn, pose, turn, platform_.yaw_rate_radps, platform_.yaw_accel_radps2);
    heading = wrap_angle(heading + turn);
    std::vector<Eigen::Vector2d> pts;
    for (std::size_t k = first; k <= i; ++k) pts.push_back(wp[k].p);
    PushedRun run(fillet_polyline(pts, motion.corner_radius_m), route.speed_mps,
                  platform_.accel_mps2, motion, rng, lead_in_yaw);
    lead_in_yaw = 0.0;
    const Pose2 start(wp[first].p.x(), wp[first].p.y(), heading);
    add_run(std::move(run), start);
    heading = heading_of(i - 1);
    pose = Pose2(wp[i].p.x(), wp[i].p.y(), heading);
    if (wp[i].stop) add(Kind::kPause, pose, route.stop_s, 0, 0);
    first = i;
  }
  add(Kind::kPause, pose, route.end_pause_s, 0, 0);
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
      return {s.start, s.dist0, 0.0, 0.0};
    case Kind::kLine: {
      double d, v;
      trapezoid_at(s.amount, s.vmax, s.accel, tau, d, v);
      const Pose2 p = s.start * Pose2(d, 0.0, 0.0);
      return {p, s.dist0 + d, v, v};
    }
    case Kind::kRun: {
      Pose2 p;
      double d, v;
      runs_[s.run].at(tau, p, d, v);
      return {p, s.dist0 + d, v, v};
    }
    case Kind::kTurn:
    default: {
      double a, w;
      trapezoid_at(std::abs(s.amount), s.vmax, s.accel, tau, a, w);
      const double sign = s.amount < 0 ? -1.0 : 1.0;
      const Pose2 p(s.start.x(), s.start.y(), wrap_angle(s.start.theta() + sign * a));
      return {p, s.dist0 + a * platform_.half_track_m, w * platform_.half_track_m, 0.0};
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

namespace traverse::sim {

Eigen::Isometry3d Trajectory::lift(const Pose2& p) const {
  CartAttitude a;
  if (floor_) a = floor_->attitude(p);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(p.theta(), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(a.pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(a.roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.x(), p.y(), a.z);
  return T;
}

Eigen::Isometry3d Trajectory::pose3(double t) const { return lift(pose(t)); }

}  // namespace traverse::sim
