#include "sensors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace traverse::sim {
namespace {
constexpr int kKnotBeams = 64;             // beams between exact pose evaluations
constexpr double kMixedPixelJumpM = 0.05;  // [m] neighbouring surfaces this far apart form a jump
}  // namespace

ScannerSim::ScannerSim(const ScannerModel& model, const Extrinsic& T_base_laser, std::string frame,
                       const World& world, const Trajectory& trajectory, const Clock& clock,
                       Rng rng, const ScanExtras& extras)
    : model_(model),
      T_base_laser_(T_base_laser.transform()),
      frame_(std::move(frame)),
      world_(world),
      trajectory_(trajectory),
      clock_(clock),
      rng_(rng),
      extras_(extras),
      effects_rng_(extras.effects_seed, 0xBEA3ULL) {
  beam_period_s_ = model_.angle_step_rad / (2.0 * std::numbers::pi) / model_.rate_hz;
  const double rate_pts_s = 1.0 / beam_period_s_;
  rate_noise_factor_ = std::sqrt(std::max(1.0, rate_pts_s / model_.range.datasheet_rate_pts_s));
  cos_grazing_limit_ = std::cos(model_.range.grazing_limit_rad);
  range_offset_m_ = rng_.uniform(-model_.range.ranging_error_m, model_.range.ranging_error_m);
  const double a0 = -0.5 * (model_.points - 1) * model_.angle_step_rad;
  // Planar sweeps cast from the base frame (directions rotated into it once); 3D sweeps rotate
  // laser-frame directions by the laser's true orientation at each moment.
  const Eigen::Matrix3d R =
      extras_.three_d ? Eigen::Matrix3d::Identity() : Eigen::Matrix3d(T_base_laser_.linear());
  for (int i = 0; i < model_.points; ++i) {
    const double a = a0 + i * model_.angle_step_rad;
    beam_dirs_laser_.push_back(R * Eigen::Vector3d(std::cos(a), std::sin(a), 0));
    if (extras_.beams.angle_jitter)
      beam_perp_.push_back(R * Eigen::Vector3d(-std::sin(a), std::cos(a), 0));
  }
}

Eigen::Vector3d ScannerSim::beam_dir(int i) {
  if (!extras_.beams.angle_jitter || model_.range.angle_jitter_rad <= 0.0)
    return beam_dirs_laser_[i];
  const double da = effects_rng_.normal(model_.range.angle_jitter_rad);
  return (beam_dirs_laser_[i] + da * beam_perp_[i]) / std::sqrt(1.0 + da * da);
}

void ScannerSim::gather_people(double time_s, const Eigen::Vector3d& origin) {
  dynamic_.clear();
  if (extras_.people)
    extras_.people->cylinders_at(time_s, origin.head<2>(), model_.range_max_m, dynamic_);
}

std::optional<RayHit> ScannerSim::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                       double t_max, double time_s) const {
  auto hit = world_.raycast(o, d, t_max, 1e-6, time_s);
  if (dynamic_.empty()) return hit;
  double best_t = hit ? hit->t : t_max;
  RayHit best = hit ? *hit : RayHit{};
  for (const Cylinder& c : dynamic_) intersect_cylinder(c, o, d, 1e-6, best_t, best);
  if (best.material == -1) return std::nullopt;
  return best;
}

double ScannerSim::noise_sigma(double range, double reflectivity, double cos_incidence) const {
  const RangeModel& m = model_.range;
  // Linear in reflectivity between the 10 % and 90 % figures, linear in range through 10 m and
  // 25 m, never below half the 10 m figure; weaker returns at slant incidence are noisier.
  const double w = std::clamp((reflectivity - 0.1) / 0.8, 0.0, 1.0);
  const double s10 = m.noise_10m_dark_m + w * (m.noise_10m_bright_m - m.noise_10m_dark_m);
  const double s25 = m.noise_25m_dark_m + w * (m.noise_25m_bright_m - m.noise_25m_dark_m);
  const double s = std::max(0.5 * s10, s10 + (range - 10.0) * (s25 - s10) / 15.0);
  return rate_noise_factor_ * s / std::sqrt(std::max(cos_incidence, 0.1));
}

float ScannerSim::measure(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                          uint8_t& intensity, double time_s) {
  return measure_beam(origin, dir, intensity, time_s).range;
}

BeamReturn ScannerSim::measure_beam(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                    uint8_t& intensity, double time_s) {
  intensity = 0;
  const RangeModel& m = model_.range;
  const BeamEffects& fx = extras_.beams;
  Eigen::Vector3d o = origin, d = dir;
  double travelled = 0.0;
  // A beam may pass glass or bounce off a mirror-like surface a few times before it returns.
  for (int interaction = 0; interaction < 4; ++interaction) {
    const auto hit = cast(o, d, model_.range_max_m - travelled, time_s);
    if (!hit) return {};
    Material person;
    if (hit->material == kPersonMaterial) person.reflectivity = extras_.people->reflectivity();
    const Material& mat = hit->material >= 0 ? world_.material(hit->material) : person;
    travelled += hit->t;
    o += hit->t * d;
    if (mat.p_return < 1.0) {
      double p_return = mat.p_return, p_mirror = mat.p_mirror;
      if (fx.incidence_materials)
        incidence_probabilities(mat, std::acos(std::min(1.0, std::abs(d.dot(hit->normal)))),
                                p_return, p_mirror);
      const double u = rng_.uniform();
      if (u >= p_return) {
        if (u < p_return + p_mirror) d -= 2.0 * d.dot(hit->normal) * hit->normal;
        continue;
      }
    }
    // Detection: received power ~ reflectivity * cos(incidence) / range^2.
    const double cos_inc = std::abs(d.dot(hit->normal));
    const double detect_range =
        m.range_at_90_percent_m * std::sqrt(std::max(mat.reflectivity * cos_inc, 1e-6) / 0.9);
    double p_detect = 1.0 / (1.0 + std::exp((travelled - detect_range) / (0.03 * detect_range)));
    const double cos_lim = cos_grazing_limit_;
    if (cos_inc < cos_lim) p_detect *= (cos_inc / cos_lim) * (cos_inc / cos_lim);
    if (rng_.uniform() >= p_detect * (1.0 - m.random_dropout)) return {};
    // The surface as it really is: off its plane by a deviation along the normal.
    double true_range = travelled;
    if (extras_.surface && hit->material != kPersonMaterial)
      true_range -= extras_.surface->deviation(o, hit->normal) / std::max(cos_inc, 0.1);
    // Range: run offset, footprint bias on slanted surfaces, noise.
    const double footprint_radius =
        0.5 * (m.beam_exit_diameter_m + m.beam_divergence_rad * travelled);
    const double tan_inc =
        std::sqrt(std::max(0.0, 1.0 - cos_inc * cos_inc)) / std::max(cos_inc, 1e-3);
    double bias = range_offset_m_ + std::min(0.5 * footprint_radius * tan_inc, 0.01);
    const double level0 = mat.reflectivity * std::sqrt(cos_inc) *
                          (1.0 - 0.3 * std::min(1.0, travelled / detect_range));
    // Range walk: a weak return crosses the detection threshold late.
    if (fx.material_bias) bias += m.dark_bias_m * std::clamp((0.9 - level0) / 0.8, 0.0, 1.0);
    const double r =
        true_range + bias + rng_.normal(noise_sigma(travelled, mat.reflectivity, cos_inc));
    if (r < model_.range_min_m || r > model_.range_max_m) return {};
    // 8-bit intensity: reflectance seen at this incidence, dimmed towards the detection limit.
    const double level = level0 + rng_.normal(0.01);
    intensity = static_cast<uint8_t>(std::lround(std::clamp(level, 0.0, 1.0) * 255.0));
    BeamReturn out;
    out.range = static_cast<float>(r);
    out.true_range = true_range;
    out.power = mat.reflectivity * cos_inc / std::max(true_range * true_range, 1e-6);
    out.point = o;
    out.normal = hit->normal;
    return out;
  }
  return {};
}

ScanData ScannerSim::sweep(int64_t k) {
  ScanData scan;
  scan.frame = frame_;
  const int n = model_.points;
  const int64_t true_first = sweep_utime(k);
  const int64_t true_last = true_first + std::llround(1e6 * beam_period_s_ * (n - 1));
  scan.angle_first = static_cast<float>(-0.5 * (n - 1) * model_.angle_step_rad);
  scan.angle_step = static_cast<float>(model_.angle_step_rad);
  scan.range_min = static_cast<float>(model_.range_min_m);
  scan.range_max = static_cast<float>(model_.range_max_m);
  scan.ranges.resize(n);
  scan.intensities.resize(n);
  returns_.assign(n, BeamReturn{});
  // Beam i is measured at utime_first + i * (utime_last - utime_first) / (n - 1), as the message
  // type defines it, from the pose the cart has at that instant.
  const double t0 = clock_.seconds(true_first);
  const double dt = 1e-6 * static_cast<double>(true_last - true_first) / (n - 1);
  if (extras_.three_d)
    sweep_3d(scan, t0, dt);
  else
    sweep_planar(scan, t0, dt);
  last_mixed_ = 0;
  const BeamEffects& fx = extras_.beams;
  if (fx.mixed_pixels)
    last_mixed_ = mix_pixels(returns_, model_.angle_step_rad, model_.range.beam_exit_diameter_m,
                             model_.range.beam_divergence_rad, kMixedPixelJumpM, effects_rng_);
  const double res = fx.quantisation ? model_.range.range_resolution_m : 0.0;
  if (fx.mixed_pixels || res > 0.0) {
    for (int i = 0; i < n; ++i) {
      double r = returns_[i].range;
      if (r <= 0.0) continue;
      if (res > 0.0) r = std::round(r / res) * res;
      if (r < model_.range_min_m || r > model_.range_max_m) r = 0.0;
      scan.ranges[i] = static_cast<float>(r);
      if (r == 0.0) scan.intensities[i] = 0;
    }
  }
  // Stamped by the scanner's clock: the sweep's span runs at the clock's rate too.
  scan.utime_first = extras_.clock.stamp(true_first, t0, k);
  scan.utime_last = scan.utime_first + std::llround(static_cast<double>(true_last - true_first) *
                                                    (1.0 + extras_.clock.drift));
  return scan;
}

void ScannerSim::sweep_planar(ScanData& scan, double t0, double dt) {
  // The true pose is evaluated exactly every kKnotBeams beams (about 0.1 ms apart) and
  // interpolated linearly in between: over 0.1 ms the cart's motion is linear to well below a
  // micrometre.
  const int n = model_.points;
  const Eigen::Vector3d t_base_laser = T_base_laser_.translation();
  Pose2 knot = trajectory_.pose(t0);
  for (int k0 = 0, last = 0; k0 < n; k0 = last) {
    const int k1 = std::min(n - 1, k0 + kKnotBeams);
    const Pose2 next = k1 > k0 ? trajectory_.pose(t0 + k1 * dt) : knot;
    const double dtheta = wrap_angle(next.theta() - knot.theta());
    const double c0 = std::cos(knot.theta()), s0 = std::sin(knot.theta());
    last = k1 == n - 1 ? n : k1;  // the last knot's beam belongs to the final interval
    const double time_s = t0 + k0 * dt;
    if (extras_.people) gather_people(time_s, Eigen::Vector3d(knot.x(), knot.y(), 0.0));
    for (int i = k0; i < last; ++i) {
      const double f = k1 > k0 ? static_cast<double>(i - k0) / (k1 - k0) : 0.0;
      const double x = knot.x() + f * (next.x() - knot.x());
      const double y = knot.y() + f * (next.y() - knot.y());
      // Heading knot + d with |d| < 1e-3 rad: cos and sin of d from their series (exact to
      // double precision at that size).
      const double d = f * dtheta, d2 = d * d;
      const double cd = 1.0 - d2 / 2.0 + d2 * d2 / 24.0,
                   sd = d * (1.0 - d2 / 6.0 + d2 * d2 / 120.0);
      const double c = c0 * cd - s0 * sd, s = s0 * cd + c0 * sd;
      auto rotate = [c, s](const Eigen::Vector3d& v) {
        return Eigen::Vector3d(c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z());
      };
      const Eigen::Vector3d origin = Eigen::Vector3d(x, y, 0.0) + rotate(t_base_laser);
      returns_[i] = measure_beam(origin, rotate(beam_dir(i)), scan.intensities[i], time_s);
      scan.ranges[i] = returns_[i].range;
    }
    knot = next;
  }
}

void ScannerSim::sweep_3d(ScanData& scan, double t0, double dt) {
  // As sweep_planar, with the laser's full 6-DoF pose at the knots, interpolated linearly
  // (rotation matrix entries too: over 0.1 ms the rotation changes by < 1e-4 rad).
  const int n = model_.points;
  auto laser_at = [&](double t) { return trajectory_.pose3(t) * T_base_laser_; };
  Eigen::Isometry3d knot = laser_at(t0);
  for (int k0 = 0, last = 0; k0 < n; k0 = last) {
    const int k1 = std::min(n - 1, k0 + kKnotBeams);
    const Eigen::Isometry3d next = k1 > k0 ? laser_at(t0 + k1 * dt) : knot;
    last = k1 == n - 1 ? n : k1;
    const double time_s = t0 + k0 * dt;
    if (extras_.people) gather_people(time_s, knot.translation());
    const Eigen::Matrix3d R0 = knot.linear(), dR = next.linear() - R0;
    const Eigen::Vector3d p0 = knot.translation(), dp = next.translation() - p0;
    for (int i = k0; i < last; ++i) {
      const double f = k1 > k0 ? static_cast<double>(i - k0) / (k1 - k0) : 0.0;
      const Eigen::Vector3d dir = ((R0 + f * dR) * beam_dir(i)).normalized();
      returns_[i] = measure_beam(p0 + f * dp, dir, scan.intensities[i], time_s);
      scan.ranges[i] = returns_[i].range;
    }
    knot = next;
  }
}

ImuSim::ImuSim(const ImuModel& model, const Extrinsic& T_base_imu, const Trajectory& trajectory,
               const Clock& clock, Rng rng, bool three_d, const SensorClock& own_clock)
    : model_(model),
      T_base_imu_(T_base_imu.transform()),
      trajectory_(trajectory),
      clock_(clock),
      rng_(rng),
      three_d_(three_d),
      own_clock_(own_clock) {
  for (int k = 0; k < 3; ++k) {
    gyro_bias0_[k] = rng_.normal(model_.gyro_bias_rad_s);
    accel_bias0_[k] = rng_.normal(model_.accel_bias_mps2);
    gyro_drift_[k] = rng_.normal(model_.gyro_bias_instability_rad_s);
    accel_drift_[k] = rng_.normal(model_.accel_bias_instability_mps2);
  }
}

void ImuSim::truth(double t, Eigen::Vector3d& omega, Eigen::Vector3d& specific_force) const {
  // Central differences of the true pose of the IMU's own point (lever arm included).
  const double h = 1e-3;
  if (three_d_) {
    // The full 6-DoF pose: body rate from the rotation between t - h and t + h, specific force
    // from the second difference of the IMU's position, gravity included.
    const Eigen::Isometry3d Tm = trajectory_.pose3(t - h) * T_base_imu_,
                            T0 = trajectory_.pose3(t) * T_base_imu_,
                            Tp = trajectory_.pose3(t + h) * T_base_imu_;
    const Eigen::AngleAxisd rot(Tm.linear().transpose() * Tp.linear());
    // The rate over [t - h, t + h] in the frame at t - h; to the frame at t (rotated by h omega).
    omega = T0.linear().transpose() * Tm.linear() * (rot.angle() * rot.axis() / (2.0 * h));
    const Eigen::Vector3d acc =
        (Tp.translation() - 2.0 * T0.translation() + Tm.translation()) / (h * h);
    specific_force = T0.linear().transpose() * (acc + Eigen::Vector3d(0, 0, model_.gravity_mps2));
    return;
  }
  const Eigen::Vector2d r = T_base_imu_.translation().head<2>();
  auto point = [&](double tt, double& theta) {
    const Pose2 T = trajectory_.pose(tt);
    theta = T.theta();
    return Eigen::Vector2d(T * r);
  };
  double th_m, th_0, th_p;
  const Eigen::Vector2d pm = point(t - h, th_m), p0 = point(t, th_0), pp = point(t + h, th_p);
  const double yaw_rate = wrap_angle(th_p - th_m) / (2.0 * h);
  const Eigen::Vector2d acc_xy = (pp - 2.0 * p0 + pm) / (h * h);
  // Specific force in world: acceleration minus gravity (gravity points down, -z).
  const Eigen::Vector3d f_world(acc_xy.x(), acc_xy.y(), model_.gravity_mps2);
  const Eigen::Matrix3d R_world_imu =
      Eigen::AngleAxisd(th_0, Eigen::Vector3d::UnitZ()).toRotationMatrix() * T_base_imu_.linear();
  omega = T_base_imu_.linear().transpose() * Eigen::Vector3d(0, 0, yaw_rate);
  specific_force = R_world_imu.transpose() * f_world;
}

ImuData ImuSim::sample(int64_t k) {
  ImuData out;
  const int64_t true_utime = sample_utime(k);
  out.utime = sample_stamp(k);
  Eigen::Vector3d omega, force;
  truth(clock_.seconds(true_utime), omega, force);
  const double dt = 1.0 / model_.rate_hz;
  // First-order Gauss-Markov drift with stationary sigma = bias instability.
  const double ag = std::exp(-dt / model_.gyro_bias_tau_s);
  const double aa = std::exp(-dt / model_.accel_bias_tau_s);
  for (int i = 0; i < 3; ++i) {
    gyro_drift_[i] = ag * gyro_drift_[i] +
                     rng_.normal(model_.gyro_bias_instability_rad_s * std::sqrt(1 - ag * ag));
    accel_drift_[i] = aa * accel_drift_[i] +
                      rng_.normal(model_.accel_bias_instability_mps2 * std::sqrt(1 - aa * aa));
    // White noise: a random walk density N gives sigma N / sqrt(dt) per sample.
    out.angular_velocity[i] = omega[i] + gyro_bias0_[i] + gyro_drift_[i] +
                              rng_.normal(model_.gyro_arw_rad_sqrt_s / std::sqrt(dt));
    out.linear_acceleration[i] = force[i] + accel_bias0_[i] + accel_drift_[i] +
                                 rng_.normal(model_.accel_vrw_mps_sqrt_s / std::sqrt(dt));
  }
  return out;
}

}  // namespace traverse::sim
