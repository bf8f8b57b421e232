// The realistic profile's motion effects, each alone: the floor pitches and rolls the cart, the
// pushed cart turns while moving, the IMU measures the 3D motion, wheel encoders see radius
// errors and slip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "config.hpp"
#include "floor.hpp"
#include "odometry.hpp"
#include "sensors.hpp"
#include "simulator.hpp"
#include "trajectory.hpp"

namespace traverse::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

FloorEffect floor_only_thresholds() {
  FloorEffect f;
  f.tile_step_sigma_m = 0.0;  // no tiles: the threshold alone
  return f;
}

RouteSpec straight(double length, double speed = 0.5) {
  RouteSpec r;
  r.world = "w";
  r.speed_mps = speed;
  r.waypoints = {{0, 0}, {length, 0}};
  return r;
}

// Pitch and roll [rad] of the 3D pose.
void tilt(const Eigen::Isometry3d& T, double& roll, double& pitch) {
  const Eigen::Matrix3d& R = T.linear();
  pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  roll = std::atan2(R(2, 1), R(2, 2));
}

TEST(Floor, AThresholdPitchesTheCartAndNothingElseDoes) {
  FloorSpec spec;
  spec.tile_size_m = 0.6;
  ThresholdSpec t;
  t.a = {5.0, -1.0};
  t.b = {5.0, 1.0};
  t.height = 0.015;
  spec.thresholds = {t};
  const FloorModel floor(spec, floor_only_thresholds(), 0.25, 1);
  double max_pitch = 0.0, max_far = 0.0;
  for (double x = 0.0; x <= 10.0; x += 0.002) {
    const CartAttitude a = floor.attitude(Pose2(x, 0.0, 0.0));
    max_pitch = std::max(max_pitch, std::abs(a.pitch));
    if (std::abs(x - 5.0) > 0.45) max_far = std::max(max_far, std::abs(a.pitch) + std::abs(a.z));
    EXPECT_NEAR(a.roll, 0.0, 1e-12);  // square across: both sides alike
  }
  // 15 mm over a 0.6 m wheelbase: 1.43 deg while one axle is on it.
  EXPECT_NEAR(max_pitch, std::atan2(0.015, 0.6), 1e-4);
  EXPECT_GT(max_pitch, 1.0 * kDeg);
  EXPECT_EQ(max_far, 0.0);
  // Front wheels up first: nose up is a negative pitch.
  EXPECT_LT(floor.attitude(Pose2(4.7, 0.0, 0.0)).pitch, -1.0 * kDeg);
  EXPECT_GT(floor.attitude(Pose2(5.3, 0.0, 0.0)).pitch, 1.0 * kDeg);
}

TEST(Floor, OfficeRouteHasTheFieldsPitchAndRoll) {
  // The office route on the realistic floor: RMS 0.1-0.3 deg, thresholds give peaks >= 1 deg.
  WorldSpec world;
  load_config("configs/worlds/office.yaml", world);
  RouteSpec route;
  load_config("configs/routes/office-x1.yaml", route);
  const Effects fx;
  Rng rng(2);
  Trajectory traj(route, PlatformConfig{}, rng, fx);
  traj.set_floor(std::make_shared<FloorModel>(world.floor, fx.floor, 0.25, 7));
  double sum2_pitch = 0.0, sum2_roll = 0.0, peak = 0.0;
  int n = 0;
  for (double t = 0.0; t < traj.duration_s(); t += 0.05) {
    double roll, pitch;
    tilt(traj.pose3(t), roll, pitch);
    sum2_pitch += pitch * pitch;
    sum2_roll += roll * roll;
    peak = std::max({peak, std::abs(pitch), std::abs(roll)});
    ++n;
  }
  const double rms_pitch = std::sqrt(sum2_pitch / n), rms_roll = std::sqrt(sum2_roll / n);
  EXPECT_GT(rms_pitch, 0.1 * kDeg);
  EXPECT_LT(rms_pitch, 0.3 * kDeg);
  EXPECT_GT(rms_roll, 0.1 * kDeg);
  EXPECT_LT(rms_roll, 0.3 * kDeg);
  EXPECT_GT(peak, 1.0 * kDeg);
}

TEST(PushedCart, TurnsWhileMovingAndVariesItsSpeed) {
  RouteSpec r;
  r.world = "w";
  r.speed_mps = 0.5;
  r.waypoints = {{0, 0}, {10, 0}, {10, 10}, {20, 10}};
  Effects fx = Effects{}.ideal();
  fx.motion.enabled = true;
  Rng rng(3);
  const Trajectory pushed(r, PlatformConfig{}, rng, fx);
  Rng rng2(3);
  const Trajectory stopping(r, PlatformConfig{}, rng2, Effects{}.ideal());
  // Stop-and-turn: at each corner the cart stands while it turns. Pushed: while it turns it moves.
  auto min_speed_while_turning = [](const Trajectory& t) {
    double lowest = 1e9;
    for (double s = 3.0; s < t.duration_s() - 3.0; s += 0.01) {
      const double yaw_rate =
          wrap_angle(t.nominal_pose(s + 0.01).theta() - t.nominal_pose(s).theta()) / 0.01;
      if (std::abs(yaw_rate) > 0.1) lowest = std::min(lowest, t.nominal_speed(s));
    }
    return lowest;
  };
  EXPECT_LT(min_speed_while_turning(stopping), 1e-9);
  EXPECT_GT(min_speed_while_turning(pushed), 0.1);
  // Cruise speed wanders: on the straight legs the speed is not one constant.
  double lo = 1e9, hi = 0.0;
  for (double s = 6.0; s < 14.0; s += 0.1) {
    lo = std::min(lo, pushed.nominal_speed(s));
    hi = std::max(hi, pushed.nominal_speed(s));
  }
  EXPECT_GT(hi - lo, 0.03);
  EXPECT_LT(hi, 0.5 * 1.5);
  // It still ends on the last waypoint and takes a shorter path than the corners.
  const Pose2 end = pushed.pose(pushed.duration_s());
  EXPECT_NEAR(end.x(), 20.0, 1e-6);
  EXPECT_NEAR(end.y(), 10.0, 1e-6);
  EXPECT_LT(pushed.length_m(), stopping.length_m());
  EXPECT_LT(pushed.duration_s(), stopping.duration_s());
}

TEST(Imu, MeasuresPitchRateAndGravityOnATiltedCart) {
  // A ramp hump under a straight drive: the 3D IMU sees a pitch rate and gravity along x; the
  // planar IMU (ideal) sees neither.
  FloorSpec spec;
  spec.tile_size_m = 0.0;
  RampSpec ramp;
  ramp.a = {2.0, 0.0};
  ramp.b = {6.0, 0.0};
  ramp.slope_rad = 2.0 * kDeg;
  spec.ramps = {ramp};
  Rng rng(1);
  PlatformConfig smooth;
  smooth.vibration.clear();
  Trajectory traj(straight(8.0), smooth, rng, Effects{}.ideal());
  traj.set_floor(std::make_shared<FloorModel>(spec, floor_only_thresholds(), 0.25, 1));
  ImuModel quiet;
  quiet.gyro_bias_rad_s = quiet.gyro_bias_instability_rad_s = quiet.gyro_arw_rad_sqrt_s = 0.0;
  quiet.accel_bias_mps2 = quiet.accel_bias_instability_mps2 = quiet.accel_vrw_mps_sqrt_s = 0.0;
  const ImuSim imu3d(quiet, Extrinsic{}, traj, Clock{0}, Rng(1), true);
  const ImuSim imu2d(quiet, Extrinsic{}, traj, Clock{0}, Rng(1), false);
  double max_rate = 0.0, max_fx = 0.0, max_fx_2d_minus_accel = 0.0;
  for (double t = 2.0; t < traj.duration_s() - 2.0; t += 0.005) {
    Eigen::Vector3d w, f, w2, f2;
    imu3d.truth(t, w, f);
    imu2d.truth(t, w2, f2);
    max_rate = std::max(max_rate, std::abs(w.y()));
    max_fx = std::max(max_fx, std::abs(f.x() - f2.x()));
    max_fx_2d_minus_accel = std::max(max_fx_2d_minus_accel, std::abs(w2.y()));
    EXPECT_NEAR(f.norm(), 9.80665, 0.05);
  }
  EXPECT_GT(max_rate, 0.005);                         // [rad/s] over the hump
  EXPECT_GT(max_fx, 9.80665 * std::sin(1.5 * kDeg));  // gravity tilted by ~2 deg
  EXPECT_EQ(max_fx_2d_minus_accel, 0.0);
}

TEST(WheelEncoders, RadiusErrorScalesDistanceAndSlipAddsNoise) {
  Rng rng(1);
  const Trajectory traj(straight(20.0), PlatformConfig{}, rng, Effects{}.ideal());
  WheelEncoderEffect e;
  e.enabled = true;
  e.slip_sigma = 0.0;
  e.track_error_sigma = 0.0;
  e.radius_error_sigma = 0.01;
  const Clock clock{0};
  OdometrySim radius_only(e, 0.25, traj, clock, Rng(5), SensorClock{});
  OdometryData last;
  for (int64_t k = 0; radius_only.sample_utime(k) <= 1e6 * traj.duration_s(); ++k)
    last = radius_only.sample(k);
  // Each wheel measures ground x r_nominal / r_true (within a tick); unequal radii also turn the
  // odometry's heading though the cart drove straight.
  const double tick_m = 2.0 * std::numbers::pi * 0.1 / e.ticks_per_rev;
  EXPECT_NEAR(last.ticks_left * tick_m, 20.0 * 0.1 / radius_only.radius_left(), tick_m);
  EXPECT_NEAR(last.ticks_right * tick_m, 20.0 * 0.1 / radius_only.radius_right(), tick_m);
  const double turn =
      (0.1 / radius_only.radius_right() - 0.1 / radius_only.radius_left()) * 20.0 / (2.0 * 0.25);
  EXPECT_NEAR(last.theta, turn, 2e-3);
  EXPECT_GT(std::abs(last.theta), 0.01);
  // Slip alone: straight on average, off by a random walk; the covariance grows and says so.
  e.radius_error_sigma = 0.0;
  e.slip_sigma = 0.02;
  OdometrySim slipping(e, 0.25, traj, clock, Rng(6), SensorClock{});
  for (int64_t k = 0; slipping.sample_utime(k) <= 1e6 * traj.duration_s(); ++k)
    last = slipping.sample(k);
  EXPECT_NEAR(last.x, 20.0, 0.1);
  EXPECT_GT(std::abs(last.x - 20.0) + std::abs(last.y), 1e-4);
  EXPECT_GT(last.pose_covariance[0], 0.0);
  EXPECT_GT(last.pose_covariance[8], 0.0);
  // Standing still: no ticks, no motion.
  OdometrySim still(e, 0.25, traj, clock, Rng(7), SensorClock{});
  for (int64_t k = 0; k < 50; ++k) last = still.sample(k);  // the first 1 s is the start pause
  EXPECT_EQ(last.ticks_left, 0);
  EXPECT_EQ(last.x, 0.0);
}

TEST(WheelEncoders, AreStampedByTheirOwnClock) {
  Rng rng(1);
  const Trajectory traj(straight(5.0), PlatformConfig{}, rng, Effects{}.ideal());
  ClockEffect c;
  c.jitter_s = 0.0;
  const SensorClock clock = SensorClock::draw(c, 9, 3);
  OdometrySim odo(WheelEncoderEffect{}, 0.25, traj, Clock{1000000}, Rng(1), clock);
  const OdometryData d = odo.sample(100);
  const double t = 100.0 / 50.0;
  EXPECT_EQ(d.utime, 1000000 + 2000000 + std::llround(1e6 * (clock.offset_s + clock.drift * t)));
  EXPECT_GT(std::abs(clock.offset_s), 0.0);
}

}  // namespace
}  // namespace traverse::sim

namespace traverse::sim {
namespace {

// Route office-s2 from 30 s on, for `duration_s`, with a SICK LMS111 (541 beams: fast).
struct OfficeS2WithLms111 {
  WorldSpec world;
  RouteSpec route;
  RunOptions run;
  explicit OfficeS2WithLms111(double duration_s) {
    load_config("configs/worlds/office.yaml", world);
    load_config("configs/routes/office-s2.yaml", route);
    route.horizontal_scanner = "sick_lms111";
    run.begin_s = 30.0;
    run.duration_s = duration_s;
  }
};

TEST(Simulator, RealisticRunWithACommonLidarAndWheelEncoders) {
  // The realistic profile end to end on two seconds of the office, the horizontal scanner swapped
  // for a SICK LMS111 and wheel encoders on: every stream at its rate, stamps in order, the 3D
  // ground truth's planar projection equal to the 2D one.
  const OfficeS2WithLms111 in(2.0);
  Effects fx;
  fx.wheel_encoders.enabled = true;
  Simulator sim(in.world, in.route, RigConfig{}, PlatformConfig{}, 4, 0, in.run, fx);
  std::map<SimEvent::Kind, int> counts;
  int64_t last = std::numeric_limits<int64_t>::min();
  double max_tilt = 0.0;
  while (auto ev = sim.next()) {
    EXPECT_GE(ev->utime, last);
    last = ev->utime;
    ++counts[ev->kind];
    if (ev->kind == SimEvent::Kind::kScanHorizontal) {
      EXPECT_EQ(ev->scan.ranges.size(), 541u);
      for (float r : ev->scan.ranges) EXPECT_LE(r, 20.0f);
    } else if (ev->kind == SimEvent::Kind::kGroundTruth) {
      const GroundTruth& g = ev->ground_truth;
      const Eigen::Matrix3d& R = g.T_world_base_3d.linear();
      EXPECT_NEAR(std::atan2(R(1, 0), R(0, 0)), g.T_world_base.theta(), 1e-12);
      EXPECT_NEAR(g.T_world_base_3d.translation().x(), g.T_world_base.x(), 1e-12);
      max_tilt = std::max(max_tilt, std::acos(std::min(1.0, R(2, 2))));
    }
  }
  EXPECT_NEAR(counts[SimEvent::Kind::kScanHorizontal], 2 * 50, 1);
  EXPECT_NEAR(counts[SimEvent::Kind::kOdometry], 2 * 50, 1);
  EXPECT_NEAR(counts[SimEvent::Kind::kImu], 2 * 200, 1);
  EXPECT_NEAR(counts[SimEvent::Kind::kGroundTruth], 2 * 200, 1);
  EXPECT_GT(max_tilt, 0.0);  // the cart tilts on the tiles
  // The processes are not told: the true extrinsic differs from the rig's, the clocks are off.
  EXPECT_NE(sim.truth().laser_horizontal.yaw, RigConfig{}.laser_horizontal.yaw);
  EXPECT_NE(sim.truth().horizontal_clock.offset_s, 0.0);
}

TEST(Simulator, GroundTruthAtAScansStampIsThePoseTheScanWasTakenFrom) {
  // Every pose the graph estimates carries a scan's stamp, on the horizontal scanner's clock; the
  // truth must be given in that time base, or a pose that is right reads off by the cart's motion
  // over the clock's error (issue 20: closures on arcs 0.7-1.2 deg off in heading). A clock far
  // off (+-1000 ppm after 30 s: 25-35 ms) and no jitter, so that a scan's true time is known.
  const OfficeS2WithLms111 in(3.0);
  Effects fx = Effects{}.ideal();
  fx.clocks.enabled = true;
  fx.clocks.drift_min_ppm = fx.clocks.drift_max_ppm = 1000.0;
  fx.clocks.jitter_s = 0.0;
  Simulator sim(in.world, in.route, RigConfig{}, PlatformConfig{}, 7, 0, in.run, fx);
  const SensorClock& clock = sim.truth().horizontal_clock;
  std::vector<GroundTruth> truth;
  std::vector<int64_t> stamps;
  while (auto ev = sim.next()) {
    if (ev->kind == SimEvent::Kind::kGroundTruth) truth.push_back(ev->ground_truth);
    if (ev->kind == SimEvent::Kind::kScanHorizontal) stamps.push_back(ev->scan.utime_first);
  }
  ASSERT_GT(truth.size(), 500u);
  ASSERT_GT(stamps.size(), 100u);
  // The truth interpolated at a stamp, as the evaluator reads it.
  const auto truth_at = [&](int64_t u) {
    auto it = std::lower_bound(truth.begin(), truth.end(), u,
                               [](const GroundTruth& g, int64_t t) { return g.utime < t; });
    EXPECT_TRUE(it != truth.begin() && it != truth.end());
    const GroundTruth& b = *it;
    const GroundTruth& a = *(it - 1);
    const double f = static_cast<double>(u - a.utime) / static_cast<double>(b.utime - a.utime);
    const Pose2 d = between(a.T_world_base, b.T_world_base);
    return a.T_world_base * Pose2(f * d.x(), f * d.y(), f * d.theta());
  };
  double max_err_m = 0.0, max_err_rad = 0.0, max_clock_shift_m = 0.0, max_clock_shift_rad = 0.0;
  for (std::size_t i = 1; i + 1 < stamps.size(); ++i) {
    // stamp = true + offset + drift x true (start 0): the scan's true first-beam time.
    const double t_true =
        (1e-6 * static_cast<double>(stamps[i]) - clock.offset_s) / (1.0 + clock.drift);
    const Pose2 taken = sim.trajectory().pose(t_true);
    const Pose2 e = between(taken, truth_at(stamps[i]));
    max_err_m = std::max(max_err_m, std::hypot(e.x(), e.y()));
    max_err_rad = std::max(max_err_rad, std::abs(e.theta()));
    // What the stamp alone would have cost read against truth in true time.
    const Pose2 shift =
        between(taken, sim.trajectory().pose(1e-6 * static_cast<double>(stamps[i])));
    max_clock_shift_m = std::max(max_clock_shift_m, std::hypot(shift.x(), shift.y()));
    max_clock_shift_rad = std::max(max_clock_shift_rad, std::abs(shift.theta()));
  }
  EXPECT_GT(max_clock_shift_m, 0.005);  // the clock's error matters here (the cart moves)
  EXPECT_LT(max_err_m, 0.0005);         // [m] linear interpolation of 200 Hz truth
  EXPECT_LT(max_err_rad, 0.0005);       // [rad]
  RecordProperty("clock_shift_m", std::to_string(max_clock_shift_m));
  RecordProperty("clock_shift_rad", std::to_string(max_clock_shift_rad));
}

}  // namespace
}  // namespace traverse::sim
