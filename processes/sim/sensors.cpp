#include "sensors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace traverse::sim {
ScannerSim::ScannerSim(const ScannerModel& model, const Extrinsic& T_base_laser, std::string frame,
                       const World& world, const Trajectory& trajectory, const Clock& clock,
                       Rng rng)
    : model_(model),
      T_base_laser_(T_base_laser.transform()),
      frame_(std::move(frame)),
      world_(world),
      trajectory_(trajectory),
      clock_(clock),
      rng_(rng) {
  beam_period_s_ = model_.angle_step_rad / (2.0 * std::numbers::pi) / model_.rate_hz;
  const double rate_pts_s = 1.0 / beam_period_s_;
  rate_noise_factor_ = std::sqrt(std::max(1.0, rate_pts_s / model_.range.datasheet_rate_pts_s));
  cos_grazing_limit_ = std::cos(model_.range.grazing_limit_rad);
  range_offset_m_ = rng_.uniform(-model_.range.ranging_error_m, model_.range.ranging_error_m);
  const double a0 = -0.5 * (model_.points - 1) * model_.angle_step_rad;
  for (int i = 0; i < model_.points; ++i) {
    const double a = a0 + i * model_.angle_step_rad;
    beam_dirs_laser_.push_back(T_base_laser_.linear() *
                               Eigen::Vector3d(std::cos(a), std::sin(a), 0));
  }
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
                          uint8_t& intensity) {
  intensity = 0;
  const RangeModel& m = model_.range;
  Eigen::Vector3d o = origin, d = dir;
  double travelled = 0.0;
  // A beam may pass glass or bounce off a mirror-like surface a few times before it returns.
  for (int interaction = 0; interaction < 4; ++interaction) {
    const auto hit = world_.raycast(o, d, model_.range_max_m - travelled);
    if (!hit) return 0.0f;
    const Material& mat = world_.material(hit->material);
    travelled += hit->t;
    o += hit->t * d;
    if (mat.p_return < 1.0) {
      const double u = rng_.uniform();
      if (u >= mat.p_return) {
        if (u < mat.p_return + mat.p_mirror) d -= 2.0 * d.dot(hit->normal) * hit->normal;
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
    if (rng_.uniform() >= p_detect * (1.0 - m.random_dropout)) return 0.0f;
    // Range: run offset, footprint bias on slanted surfaces, noise.
    const double footprint_radius =
        0.5 * (m.beam_exit_diameter_m + m.beam_divergence_rad * travelled);
    const double tan_inc =
        std::sqrt(std::max(0.0, 1.0 - cos_inc * cos_inc)) / std::max(cos_inc, 1e-3);
    const double bias = range_offset_m_ + std::min(0.5 * footprint_radius * tan_inc, 0.01);
    const double r =
        travelled + bias + rng_.normal(noise_sigma(travelled, mat.reflectivity, cos_inc));
    if (r < model_.range_min_m || r > model_.range_max_m) return 0.0f;
    // 8-bit intensity: reflectance seen at this incidence, dimmed towards the detection limit.
    const double level = mat.reflectivity * std::sqrt(cos_inc) *
                             (1.0 - 0.3 * std::min(1.0, travelled / detect_range)) +
                         rng_.normal(0.01);
    intensity = static_cast<uint8_t>(std::lround(std::clamp(level, 0.0, 1.0) * 255.0));
    return static_cast<float>(r);
  }
  return 0.0f;
}

ScanData ScannerSim::sweep(int64_t k) {
  ScanData scan;
  scan.frame = frame_;
  const int n = model_.points;
  scan.utime_first = sweep_utime(k);
  scan.utime_last = scan.utime_first + std::llround(1e6 * beam_period_s_ * (n - 1));
  scan.angle_first = static_cast<float>(-0.5 * (n - 1) * model_.angle_step_rad);
  scan.angle_step = static_cast<float>(model_.angle_step_rad);
  scan.range_min = static_cast<float>(model_.range_min_m);
  scan.range_max = static_cast<float>(model_.range_max_m);
  scan.ranges.resize(n);
  scan.intensities.resize(n);
  // Beam i is measured at utime_first + i * (utime_last - utime_first) / (n - 1), as the message
  // type defines it, from the pose the cart has at that instant. The true pose is evaluated
  // exactly every kKnotBeams beams (about 0.1 ms apart) and interpolated linearly in between:
  // over 0.1 ms the cart's motion is linear to well below a micrometre.
  constexpr int kKnotBeams = 64;
  const double t0 = clock_.seconds(scan.utime_first);
  const double dt = 1e-6 * static_cast<double>(scan.utime_last - scan.utime_first) / (n - 1);
  const Eigen::Vector3d t_base_laser = T_base_laser_.translation();
  Pose2 knot = trajectory_.pose(t0);
  for (int k0 = 0, last = 0; k0 < n; k0 = last) {
    const int k1 = std::min(n - 1, k0 + kKnotBeams);
    const Pose2 next = k1 > k0 ? trajectory_.pose(t0 + k1 * dt) : knot;
    const double dtheta = wrap_angle(next.theta() - knot.theta());
    const double c0 = std::cos(knot.theta()), s0 = std::sin(knot.theta());
    last = k1 == n - 1 ? n : k1;  // the last knot's beam belongs to the final interval
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
      scan.ranges[i] = measure(origin, rotate(beam_dirs_laser_[i]), scan.intensities[i]);
    }
    knot = next;
  }
  return scan;
}

ImuSim::ImuSim(const ImuModel& model, const Extrinsic& T_base_imu, const Trajectory& trajectory,
               const Clock& clock, Rng rng)
    : model_(model),
      T_base_imu_(T_base_imu.transform()),
      trajectory_(trajectory),
      clock_(clock),
      rng_(rng) {
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
  out.utime = sample_utime(k);
  Eigen::Vector3d omega, force;
  truth(clock_.seconds(out.utime), omega, force);
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
