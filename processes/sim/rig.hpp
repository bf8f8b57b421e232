// The sensor rig of the cart (frames base, laser_horizontal, laser_profile, imu) and the error
// models of its sensors, as one config struct. configs/rig.yaml restates these defaults so that the
// frontend and mapper read the same extrinsics the simulator used.
//
// Sources of the figures (manufacturers' published specification sheets):
// - FARO Laser Scanner Focus3D 120 / 120S spec sheet: ranging error +-2 mm (systematic, 10 m and
//   25 m, 90 % and 10 % reflectivity); ranging noise of raw data at 122,000 pts/s: 0.6 mm at 10 m
//   and 0.95 mm at 25 m on 90 % reflectivity, 1.2 mm and 2.2 mm on 10 %; beam diameter at exit
//   3.8 mm, divergence 0.19 mrad; range 120 m on a 90 % target at normal incidence.
// - FARO Focus3D X 330 spec sheet: ranging error +-2 mm; raw noise at 122,000 pts/s 0.3 mm
//   (10 m) and 0.5 mm (25 m) on 90 %, 0.4 mm and 0.8 mm on 10 %; beam diameter at exit 2.25 mm,
//   divergence 0.3 mrad; range 330 m.
// - Rotation rates, angular steps and points per sweep: seed 000, Table 1 (47.7 Hz, 0.613 mrad,
//   8536 points; 59.7 Hz, 0.767 mrad, 6828 points); profile scanner 30 Hz, 244,000 pts/s, 6 m
//   maximum range, horizontal scanner set to 41 m (seed 000, section 3).
// - NovAtel SPAN UIMU-LCI (tactical grade, fibre-optic gyros) product sheet: gyro bias stability
//   1.0 deg/h, angle random walk 0.05 deg/sqrt(h); accelerometer bias 1.0 mg. Its velocity random
//   walk is not on the sheet; 0.05 m/s/sqrt(h), a usual tactical-grade figure, is used.
// - FARO Focus3D X 330 spec sheet: angular accuracy 19 arcsec (9.2e-5 rad) for both axes; used as
//   the 1 sigma angle jitter of both FARO models.
// - SICK LMS1xx operating instructions and SICK's note on LMS measurement errors: systematic error
//   +-30 mm typical (+-40 mm maximum), statistical error 12 mm typical (20 mm maximum); beam
//   diameter 8 mm at the cover growing by 15 mrad (distance x 0.015 rad + 8 mm); 25 or 50 Hz,
//   0.25 or 0.5 deg over 270 deg, 20 m operating range, 18 m on 10 % reflectivity.
// - Hokuyo UTM-30LX spec sheet: 40 Hz (25 ms per scan), 0.25 deg over 270 deg, 30 m (60 m
//   maximum), accuracy +-30 mm to 10 m and +-50 mm to 30 m.
// - SICK LMS200 (the scanner of the CARMEN/Kummerle logs) technical description: 75 Hz mirror,
//   180 deg at 1 deg or 0.5 deg (two interlaced revolutions), 80 m (cm mode; 8191 cm reads as no
//   return), 10 m on 10 % reflectivity; statistical error 5 mm (1 sigma), systematic +-15 mm (mm
//   mode, 1-8 m); its beam is taken as the LMS1xx's (8 mm + 15 mrad), the sheet not giving it.
// These figures were taken from the published sheets as remembered (the LMS1xx's from the
// operating instructions); check them against a copy of the sheet before quoting results that
// depend on them.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace traverse::sim {

// A rigid transform T_base_sensor: sensor origin in base [m] and its orientation as roll, pitch,
// yaw [rad] (R = Rz(yaw) Ry(pitch) Rx(roll)).
struct Extrinsic {
  double x = 0, y = 0, z = 0, roll = 0, pitch = 0, yaw = 0;
  template <class V>
  void visit(V& v) {
    v("x", x);
    v("y", y);
    v("z", z);
    v("roll", roll);
    v("pitch", pitch);
    v("yaw", yaw);
  }
  Eigen::Isometry3d transform() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    T.translation() = Eigen::Vector3d(x, y, z);
    return T;
  }
};

// Range errors and detection of a phase-shift scanner.
struct RangeModel {
  double noise_10m_bright_m = 0.0006;    // [m] 1 sigma at 10 m on 90 % reflectivity
  double noise_25m_bright_m = 0.00095;   // [m] at 25 m, 90 %
  double noise_10m_dark_m = 0.0012;      // [m] at 10 m, 10 %
  double noise_25m_dark_m = 0.0022;      // [m] at 25 m, 10 %
  double datasheet_rate_pts_s = 122000;  // [points/s] rate the noise figures are given at; noise
                                         // grows with sqrt(rate / this) (shorter integration)
  double ranging_error_m = 0.002;        // [m] +- systematic error: a per-run offset drawn in it
  double beam_exit_diameter_m = 0.0038;  // [m]
  double beam_divergence_rad = 0.00019;  // [rad] full angle
  double range_at_90_percent_m = 120.0;  // [m] detection range on 90 % at normal incidence;
                                         // scales with sqrt(reflectivity * cos(incidence))
  double grazing_limit_rad = 1.396;      // [rad] (80 deg) beyond this incidence returns fade out
  double random_dropout = 0.0002;        // probability a beam returns nothing for no reason
  // Used by the simulator's realistic beam effects only:
  double angle_jitter_rad = 9.2e-5;  // [rad] 1 sigma of a beam's true angle about its nominal one
  double dark_bias_m = 0.001;        // [m] range walk: a 10 % target reads this much longer than a
                                     // 90 % one (linear in the returned level in between)
  double range_resolution_m = 0.0;   // [m] ranges are output in steps of this (0: continuous)
  template <class V>
  void visit(V& v) {
    v("angle_jitter_rad", angle_jitter_rad);
    v("dark_bias_m", dark_bias_m);
    v("range_resolution_m", range_resolution_m);
    v("noise_10m_bright_m", noise_10m_bright_m);
    v("noise_25m_bright_m", noise_25m_bright_m);
    v("noise_10m_dark_m", noise_10m_dark_m);
    v("noise_25m_dark_m", noise_25m_dark_m);
    v("datasheet_rate_pts_s", datasheet_rate_pts_s);
    v("ranging_error_m", ranging_error_m);
    v("beam_exit_diameter_m", beam_exit_diameter_m);
    v("beam_divergence_rad", beam_divergence_rad);
    v("range_at_90_percent_m", range_at_90_percent_m);
    v("grazing_limit_rad", grazing_limit_rad);
    v("random_dropout", random_dropout);
  }
};

// A rotating planar scanner: one sweep per revolution, `points` beams `angle_step_rad` apart
// centred on the x axis of its frame, measured one after another at the mirror's pace.
struct ScannerModel {
  std::string name;
  double rate_hz = 47.7;             // [Hz] sweeps per second (mirror revolutions)
  int points = 8536;                 // beams per sweep
  double angle_step_rad = 0.613e-3;  // [rad]
  double range_min_m = 0.6;          // [m]
  double range_max_m = 41.0;         // [m] set in the scanner (seed 000: 41 m)
  RangeModel range;
  template <class V>
  void visit(V& v) {
    v("name", name);
    v("rate_hz", rate_hz);
    v("points", points);
    v("angle_step_rad", angle_step_rad);
    v("range_min_m", range_min_m);
    v("range_max_m", range_max_m);
    v("range", range);
  }
};

struct ImuModel {
  double rate_hz = 200.0;                        // [Hz] (seed 000: 200 Hz)
  double gyro_bias_rad_s = 4.85e-6;              // [rad/s] 1 sigma turn-on bias (1 deg/h)
  double gyro_bias_instability_rad_s = 4.85e-6;  // [rad/s] 1 sigma of the drifting part (1 deg/h)
  double gyro_bias_tau_s = 3600.0;               // [s] Gauss-Markov correlation time of the drift
  double gyro_arw_rad_sqrt_s = 1.454e-5;         // [rad/sqrt(s)] (0.05 deg/sqrt(h))
  double accel_bias_mps2 = 9.81e-3;              // [m/s^2] 1 sigma turn-on bias (1 mg)
  double accel_bias_instability_mps2 = 9.81e-4;  // [m/s^2] drifting part (0.1 mg)
  double accel_bias_tau_s = 3600.0;              // [s]
  double accel_vrw_mps_sqrt_s = 8.33e-4;         // [m/s/sqrt(s)] (0.05 m/s/sqrt(h))
  double gravity_mps2 = 9.80665;                 // [m/s^2]
  template <class V>
  void visit(V& v) {
    v("rate_hz", rate_hz);
    v("gyro_bias_rad_s", gyro_bias_rad_s);
    v("gyro_bias_instability_rad_s", gyro_bias_instability_rad_s);
    v("gyro_bias_tau_s", gyro_bias_tau_s);
    v("gyro_arw_rad_sqrt_s", gyro_arw_rad_sqrt_s);
    v("accel_bias_mps2", accel_bias_mps2);
    v("accel_bias_instability_mps2", accel_bias_instability_mps2);
    v("accel_bias_tau_s", accel_bias_tau_s);
    v("accel_vrw_mps_sqrt_s", accel_vrw_mps_sqrt_s);
    v("gravity_mps2", gravity_mps2);
  }
};

inline ScannerModel focus3d_120s() { return {"focus3d_120s", 47.7, 8536, 0.613e-3, 0.6, 41.0, {}}; }

inline ScannerModel focus3d_x330() {
  RangeModel r;
  r.noise_10m_bright_m = 0.0003;
  r.noise_25m_bright_m = 0.0005;
  r.noise_10m_dark_m = 0.0004;
  r.noise_25m_dark_m = 0.0008;
  r.beam_exit_diameter_m = 0.00225;
  r.beam_divergence_rad = 0.0003;
  r.range_at_90_percent_m = 330.0;
  return {"focus3d_x330", 59.7, 6828, 0.767e-3, 0.6, 41.0, r};
}

// The profile scanner: 244,000 points/s at 30 Hz is 8133 points over the full circle.
inline ScannerModel profile_focus3d() {
  return {
      "focus3d_120s_profile", 30.0, 8133, 2.0 * std::numbers::pi * 30.0 / 244000.0, 0.6, 6.0, {}};
}

// The common 2D lidars most users own, and the one of the CARMEN logs. Noise is flat in range
// (datasheet_rate_pts_s equals the scanner's own rate, so no rate scaling).
inline ScannerModel sick_class(std::string name, double rate_hz, int points, double step_deg,
                               double range_max_m, double range_at_90_m, double noise_m,
                               double noise_far_m, double ranging_error_m, double dark_bias_m,
                               double resolution_m) {
  RangeModel r;
  r.noise_10m_bright_m = r.noise_10m_dark_m = noise_m;
  r.noise_25m_bright_m = r.noise_25m_dark_m = noise_far_m;
  const double step = step_deg * std::numbers::pi / 180.0;
  r.datasheet_rate_pts_s = rate_hz * 2.0 * std::numbers::pi / step;
  r.ranging_error_m = ranging_error_m;
  r.beam_exit_diameter_m = 0.008;
  r.beam_divergence_rad = 0.015;
  r.range_at_90_percent_m = range_at_90_m;
  r.angle_jitter_rad = 0.0;  // no figure on these sheets
  r.dark_bias_m = dark_bias_m;
  r.range_resolution_m = resolution_m;
  return {std::move(name), rate_hz, points, step, 0.05, range_max_m, r};
}
// Systematic errors split evenly between a per-run offset and the range walk with darkness.
inline ScannerModel sick_lms111() {
  return sick_class("sick_lms111", 50.0, 541, 0.5, 20.0, 54.0, 0.012, 0.012, 0.015, 0.015, 0.001);
}
inline ScannerModel hokuyo_utm30lx() {
  ScannerModel m =
      sick_class("hokuyo_utm30lx", 40.0, 1081, 0.25, 30.0, 60.0, 0.015, 0.025, 0.015, 0.015, 0.001);
  m.range.beam_exit_diameter_m = 0.01;  // not on the sheet: taken like the LMS1xx class,
  m.range.beam_divergence_rad = 0.01;   // a little narrower
  return m;
}
inline ScannerModel sick_lms200(int points, double step_deg) {
  return sick_class(points > 200 ? "sick_lms200_half_deg" : "sick_lms200", 75.0, points, step_deg,
                    81.0, 30.0, 0.005, 0.005, 0.0075, 0.0075, 0.01);
}

struct RigConfig {
  // Horizontal scanner about 50 cm above the floor (seed 000, section 3).
  Extrinsic laser_horizontal{0.0, 0.0, 0.5, 0.0, 0.0, 0.0};
  // Profile scanner at the front, 1.0 m up; its spin axis (frame z) points forward and 10 deg up,
  // so its scan plane is tilted 10 deg from the vertical plane across the direction of travel.
  Extrinsic laser_profile{0.45, 0.0, 1.0, 0.0, 80.0 * std::numbers::pi / 180.0, 0.0};
  Extrinsic imu{-0.10, 0.05, 0.30, 0.0, 0.0, 0.0};
  std::vector<ScannerModel> horizontal_scanners = {focus3d_120s(),        focus3d_x330(),
                                                   sick_lms111(),         hokuyo_utm30lx(),
                                                   sick_lms200(181, 1.0), sick_lms200(361, 0.5)};
  ScannerModel profile_scanner = profile_focus3d();
  ImuModel imu_model;
  double ground_truth_rate_hz = 200.0;  // [Hz]
  template <class V>
  void visit(V& v) {
    v("laser_horizontal", laser_horizontal);
    v("laser_profile", laser_profile);
    v("imu", imu);
    v("horizontal_scanners", horizontal_scanners);
    v("profile_scanner", profile_scanner);
    v("imu_model", imu_model);
    v("ground_truth_rate_hz", ground_truth_rate_hz);
  }
};

}  // namespace traverse::sim
