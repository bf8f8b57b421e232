#include "pushed_path.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace traverse::sim {

std::vector<PathPiece> fillet_polyline(const std::vector<Eigen::Vector2d>& p, double max_radius) {
  std::vector<PathPiece> out;
  const std::size_t n = p.size();
  if (n < 2) return out;
  // Tangent length at each interior corner: r tan(|turn| / 2), at most 45 % of either leg.
  std::vector<double> tangent(n, 0.0), radius(n, 0.0), turn(n, 0.0);
  auto heading = [&](std::size_t i) {
    const Eigen::Vector2d d = p[i + 1] - p[i];
    return std::atan2(d.y(), d.x());
  };
  for (std::size_t i = 1; i + 1 < n; ++i) {
    turn[i] = wrap_angle(heading(i) - heading(i - 1));
    const double half = 0.5 * std::abs(turn[i]);
    if (half < 1e-6) continue;
    const double leg = std::min((p[i] - p[i - 1]).norm(), (p[i + 1] - p[i]).norm());
    radius[i] = std::min(max_radius, 0.45 * leg / std::tan(half));
    tangent[i] = radius[i] * std::tan(half);
  }
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double h = heading(i);
    const Eigen::Vector2d dir(std::cos(h), std::sin(h));
    const Eigen::Vector2d a = p[i] + tangent[i] * dir;
    const double len = (p[i + 1] - p[i]).norm() - tangent[i] - tangent[i + 1];
    if (len > 1e-9) out.push_back({Pose2(a.x(), a.y(), h), len, 0.0});
    if (i + 2 < n && tangent[i + 1] > 0.0) {
      const Eigen::Vector2d b = p[i + 1] - tangent[i + 1] * dir;
      const double k = (turn[i + 1] > 0 ? 1.0 : -1.0) / radius[i + 1];
      out.push_back({Pose2(b.x(), b.y(), h), std::abs(turn[i + 1]) * radius[i + 1], k});
    }
  }
  return out;
}

PushedRun::PushedRun(std::vector<PathPiece> pieces, double cruise_mps, double accel_mps2,
                     const MotionEffect& motion, Rng& rng, double start_yaw_rad)
    : pieces_(std::move(pieces)),
      lead_in_slope_(std::tan(start_yaw_rad)),
      lead_in_m_(motion.start_settle_m) {
  if (pieces_.empty()) throw std::runtime_error("pushed run without a path");
  for (const auto& piece : pieces_) {
    piece_s0_.push_back(length_);
    length_ += piece.length;
  }
  // Speed wanders as two sinusoids of the travelled distance with random phases.
  double phase[2], k[2];
  for (int i = 0; i < 2; ++i) {
    phase[i] = rng.uniform(0.0, 2.0 * std::numbers::pi);
    k[i] = 2.0 * std::numbers::pi / (motion.speed_wavelength_m * (i == 0 ? 1.0 : 0.43));
    weave_phase_[i] = rng.uniform(0.0, 2.0 * std::numbers::pi);
    weave_k_[i] = 2.0 * std::numbers::pi / (motion.weave_wavelength_m * (i == 0 ? 1.0 : 0.37));
    weave_amp_[i] = motion.weave_m;  // two equal sinusoids: 1 sigma = weave_m
  }
  const int n = std::max(2, static_cast<int>(std::ceil(length_ / ds_)) + 1);
  ds_ = length_ / (n - 1);
  std::vector<double> vmax(n);
  for (int i = 0; i < n; ++i) {
    const double s = i * ds_;
    double curvature = 0.0;
    centre_line(s, curvature);
    const double wander =
        motion.speed_variation * (std::sin(k[0] * s + phase[0]) + std::sin(k[1] * s + phase[1]));
    vmax[i] = cruise_mps * std::max(0.3, 1.0 + wander);
    if (std::abs(curvature) > 1e-9)
      vmax[i] = std::min(vmax[i], std::sqrt(motion.lateral_accel_mps2 / std::abs(curvature)));
  }
  // Forward and backward passes under the acceleration limit, standstill at both ends.
  v_.assign(n, 0.0);
  for (int i = 1; i < n; ++i)
    v_[i] = std::min(vmax[i], std::sqrt(v_[i - 1] * v_[i - 1] + 2.0 * accel_mps2 * ds_));
  v_[n - 1] = 0.0;
  for (int i = n - 2; i >= 0; --i)
    v_[i] = std::min(v_[i], std::sqrt(v_[i + 1] * v_[i + 1] + 2.0 * accel_mps2 * ds_));
  v_[0] = 0.0;
  t_.assign(n, 0.0);
  for (int i = 1; i < n; ++i) t_[i] = t_[i - 1] + 2.0 * ds_ / std::max(v_[i - 1] + v_[i], 1e-9);
}

Pose2 PushedRun::centre_line(double s, double& curvature) const {
  s = std::clamp(s, 0.0, length_);
  auto it = std::upper_bound(piece_s0_.begin(), piece_s0_.end(), s);
  const std::size_t i = it == piece_s0_.begin() ? 0 : (it - piece_s0_.begin()) - 1;
  const PathPiece& p = pieces_[i];
  const double u = std::min(s - piece_s0_[i], p.length);
  curvature = p.curvature;
  if (std::abs(p.curvature) < 1e-12) return p.start * Pose2(u, 0.0, 0.0);
  const double a = u * p.curvature, r = 1.0 / p.curvature;
  return p.start * Pose2(r * std::sin(a), r * (1.0 - std::cos(a)), a);
}

double PushedRun::weave(double s, double& slope) const {
  // Faded in and out over the first and last metre, so runs start and end on the waypoints.
  const double fade_len = std::min(1.0, 0.5 * length_);
  auto fade = [&](double x) {
    const double t = std::clamp(x / fade_len, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
  };
  auto w = [&](double x) {
    double sum = 0.0;
    for (int i = 0; i < 2; ++i) sum += weave_amp_[i] * std::sin(weave_k_[i] * x + weave_phase_[i]);
    return sum * fade(x) * fade(length_ - x);
  };
  const double h = 1e-3;
  slope = (w(std::min(s + h, length_)) - w(std::max(s - h, 0.0))) / (2.0 * h);
  // The start yaw's lead-in: y = tan(yaw) s (1 - s / L)^2, slope tan(yaw) at s = 0, back on
  // the line with slope 0 at s = L.
  const double L = std::min(lead_in_m_, length_);
  double lead = 0.0;
  if (s < L) {
    const double r = 1.0 - s / L;
    lead = lead_in_slope_ * s * r * r;
    slope += lead_in_slope_ * r * (1.0 - 3.0 * s / L);
  }
  return w(s) + lead;
}

Pose2 PushedRun::pose_at(double s) const {
  double curvature, slope;
  const Pose2 c = centre_line(s, curvature);
  const double lateral = weave(s, slope);
  return c * Pose2(0.0, lateral, std::atan(slope));
}

void PushedRun::at(double tau, Pose2& pose, double& s, double& v) const {
  tau = std::clamp(tau, 0.0, duration_s());
  auto it = std::upper_bound(t_.begin(), t_.end(), tau);
  const std::size_t k = std::min<std::size_t>(
      t_.size() - 2, it == t_.begin() ? 0 : static_cast<std::size_t>(it - t_.begin()) - 1);
  // Constant acceleration between grid points.
  const double a = (v_[k + 1] * v_[k + 1] - v_[k] * v_[k]) / (2.0 * ds_);
  const double d = tau - t_[k];
  s = std::min(length_, k * ds_ + v_[k] * d + 0.5 * a * d * d);
  v = std::max(0.0, v_[k] + a * d);
  pose = pose_at(s);
}

}  // namespace traverse::sim
