#include "sensors.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "config.hpp"
#include "simulator.hpp"

namespace traverse::sim {
namespace {

// A wall across the x axis at x = 10 (and whatever else a test adds), nothing else.
WorldSpec wall_world(double reflectivity, double x = 10.0) {
  WorldSpec w;
  w.name = "wall";
  w.materials = {
      {"wall", reflectivity, 1.0, 0.0}, {"floor", 0.3, 1.0, 0.0}, {"glass", 0.08, 0.1, 0.0}};
  w.walls = {{{{x, -60}, {x, 60}}, {0.0, 3.0}, false, "wall", ""}};
  return w;
}

// The cart standing at the origin facing +x for 10 s, then driving 5 m along +x.
RouteSpec standing_then_driving() {
  RouteSpec r;
  r.world = "wall";
  r.speed_mps = 0.5;
  r.waypoints = {{0, 0}, {5, 0}};
  r.start_pause_s = 10.0;
  return r;
}

struct Rig {
  explicit Rig(const WorldSpec& spec, const RouteSpec& route = standing_then_driving())
      : world(spec), rng(1), trajectory(route, PlatformConfig{}, rng, Effects{}.ideal()) {}
  World world;
  Rng rng;
  Trajectory trajectory;
  Clock clock{1000000};
};

ScannerModel exact_offset_model() {
  ScannerModel m = focus3d_120s();
  m.range.ranging_error_m = 0.0;  // no per-run offset, to see the other errors alone
  return m;
}

TEST(Scanner, ScanOfAKnownWallFromAKnownPoseGivesTheExpectedRanges) {
  Rig rig(wall_world(0.9));
  ScannerSim scanner(exact_offset_model(), Extrinsic{0, 0, 0.5, 0, 0, 0}, "laser_horizontal",
                     rig.world, rig.trajectory, rig.clock, Rng(5));
  const ScanData scan = scanner.sweep(0);
  ASSERT_EQ(scan.ranges.size(), 8536u);
  int checked = 0;
  double sum = 0.0;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double a = scan.angle_first + i * scan.angle_step;
    const double expected = 10.0 / std::cos(a);
    if (std::abs(a) > std::acos(10.0 / 41.0) + 0.01) {
      EXPECT_EQ(scan.ranges[i], 0.0f) << "beam " << i << " sees nothing within 41 m";
      continue;
    }
    if (std::abs(a) > 0.5 || scan.ranges[i] == 0.0f) continue;
    // 120S at 488k points/s: 2 x 0.6 mm at 10 m on a bright wall, more at an angle; the beam
    // footprint adds a bias of at most a few millimetres at these incidences.
    const double err = scan.ranges[i] - expected;
    EXPECT_LT(std::abs(err), 0.010) << "beam " << i;
    sum += err;
    ++checked;
  }
  EXPECT_GT(checked, 1500);
  EXPECT_LT(std::abs(sum / checked), 0.002);
}

TEST(Scanner, DarkDistantOrGrazingSurfacesDropOut) {
  auto returns = [](const WorldSpec& spec, double a_lo, double a_hi) {
    Rig rig(spec);
    ScannerSim scanner(exact_offset_model(), Extrinsic{0, 0, 0.5, 0, 0, 0}, "laser_horizontal",
                       rig.world, rig.trajectory, rig.clock, Rng(9));
    const ScanData scan = scanner.sweep(0);
    int n = 0, got = 0;
    for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
      const double a = scan.angle_first + i * scan.angle_step;
      if (a < a_lo || a > a_hi) continue;
      ++n;
      got += scan.ranges[i] > 0.0f;
    }
    return static_cast<double>(got) / n;
  };
  // A black wall (3 %) answers at 10 m but not at 30 m; a white one answers at 30 m.
  EXPECT_GT(returns(wall_world(0.03, 10.0), -0.2, 0.2), 0.95);
  EXPECT_LT(returns(wall_world(0.03, 30.0), -0.2, 0.2), 0.05);
  EXPECT_GT(returns(wall_world(0.9, 30.0), -0.2, 0.2), 0.95);
  // A wall along the beams (y = 1): met at grazing incidence beyond 85 degrees for small angles.
  WorldSpec along = wall_world(0.9, 100.0);
  along.walls.push_back({{{0.5, 1.0}, {60.0, 1.0}}, {0.0, 3.0}, false, "wall", ""});
  EXPECT_LT(returns(along, 0.025, 0.087), 0.35);  // incidence 85-88.6 deg
  EXPECT_GT(returns(along, 0.6, 1.0), 0.95);      // incidence 33-56 deg
}

TEST(Scanner, GlassPassesMostBeams) {
  WorldSpec spec = wall_world(0.9);
  spec.walls.push_back({{{5.0, -60}, {5.0, 60}}, {0.0, 3.0}, false, "glass", ""});
  Rig rig(spec);
  ScannerSim scanner(exact_offset_model(), Extrinsic{0, 0, 0.5, 0, 0, 0}, "laser_horizontal",
                     rig.world, rig.trajectory, rig.clock, Rng(2));
  const ScanData scan = scanner.sweep(0);
  int on_glass = 0, behind = 0;
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    const double a = scan.angle_first + i * scan.angle_step;
    if (std::abs(a) > 0.6 || scan.ranges[i] == 0.0f) continue;
    const double x = scan.ranges[i] * std::cos(a);
    on_glass += std::abs(x - 5.0) < 0.05;
    behind += std::abs(x - 10.0) < 0.05;
  }
  const double share = static_cast<double>(on_glass) / (on_glass + behind);
  EXPECT_GT(share, 0.06);
  EXPECT_LT(share, 0.14);
}

TEST(Scanner, EveryBeamIsMeasuredFromThePoseAtItsOwnTime) {
  // Driving straight at the wall at 0.5 m/s: a sweep lasts 17.5 ms, so the beam straight ahead
  // (in the middle of the sweep) is 4.4 mm closer than it would be from the sweep's first pose.
  Rig rig(wall_world(0.9));
  ScannerModel model = exact_offset_model();
  model.range.noise_10m_bright_m = model.range.noise_25m_bright_m = 1e-6;
  model.range.noise_10m_dark_m = model.range.noise_25m_dark_m = 1e-6;
  ScannerSim scanner(model, Extrinsic{0, 0, 0.5, 0, 0, 0}, "laser_horizontal", rig.world,
                     rig.trajectory, rig.clock, Rng(3));
  // A sweep starting 2 s into the drive, at cruise speed.
  int64_t k = 0;
  while (rig.clock.seconds(scanner.sweep_utime(k)) < 12.0) ++k;
  const ScanData scan = scanner.sweep(k);
  const int n = static_cast<int>(scan.ranges.size());
  const int mid = n / 2;
  const double t_mid = rig.clock.seconds(scan.utime_first) +
                       1e-6 * (scan.utime_last - scan.utime_first) * mid / (n - 1);
  const double x_mid = rig.trajectory.pose(t_mid).x();
  const double x_first = rig.trajectory.pose(rig.clock.seconds(scan.utime_first)).x();
  EXPECT_GT(x_mid - x_first, 0.004);
  const double a = scan.angle_first + mid * scan.angle_step;
  const double heading = rig.trajectory.pose(t_mid).theta();
  // Range from the pose at the beam's time (vibration included).
  const Pose2 T = rig.trajectory.pose(t_mid);
  const double expected = (10.0 - T.x()) / std::cos(a + heading);
  EXPECT_NEAR(scan.ranges[mid], expected, 2e-4);
}

TEST(Imu, IntegratesToTheTrueHeadingChangeAndMeasuresGravity) {
  RouteSpec r;
  r.world = "wall";
  r.speed_mps = 0.5;
  r.waypoints = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  Rig rig(wall_world(0.9), r);
  ImuSim imu(ImuModel{}, Extrinsic{-0.1, 0.05, 0.3, 0, 0, 0}, rig.trajectory, rig.clock, Rng(4));
  double heading = 0.0, prev_rate = 0.0, truth = 0.0;
  Eigen::Vector3d force_sum = Eigen::Vector3d::Zero();
  const double dt = 1.0 / 200.0;
  int n = 0;
  for (int64_t k = 0; rig.clock.seconds(imu.sample_utime(k)) <= rig.trajectory.duration_s(); ++k) {
    const ImuData s = imu.sample(k);
    if (k > 0) heading += 0.5 * (prev_rate + s.angular_velocity.z()) * dt;
    prev_rate = s.angular_velocity.z();
    force_sum += s.linear_acceleration;
    ++n;
    if (k > 0) {
      const double t = rig.clock.seconds(s.utime);
      truth += wrap_angle(rig.trajectory.pose(t).theta() - rig.trajectory.pose(t - dt).theta());
    }
  }
  EXPECT_NEAR(truth, std::numbers::pi, 0.01);  // two left turns of 90 deg
  // Tactical grade over ~20 s: bias ~1e-5 rad/s and random walk ~7e-5 rad: well under 1 mrad.
  EXPECT_NEAR(heading, truth, 1e-3);
  EXPECT_NEAR(force_sum.z() / n, 9.80665, 0.05);
  EXPECT_LT(std::abs(force_sum.x() / n), 0.05);
}

TEST(Simulator, StreamsHaveTheSensorsRatesSizesAndTimes) {
  WorldSpec world;
  load_config("configs/worlds/office.yaml", world);
  RouteSpec route;
  load_config("configs/routes/office-s2.yaml", route);
  RunOptions run;
  run.begin_s = 10.0;
  run.duration_s = 2.0;
  Simulator sim(world, route, RigConfig{}, PlatformConfig{}, 1, 1000000000, run, Effects{}.ideal());
  int counts[4] = {0, 0, 0, 0};
  int64_t last_utime = 0, prev_scan = -1;
  while (auto ev = sim.next()) {
    EXPECT_GE(ev->utime, last_utime);
    last_utime = ev->utime;
    const int kind = static_cast<int>(ev->kind);
    ++counts[kind];
    if (ev->kind == SimEvent::Kind::kScanHorizontal) {
      EXPECT_EQ(ev->scan.ranges.size(), 8536u);
      EXPECT_FLOAT_EQ(ev->scan.angle_step, 0.613e-3f);
      // 8535 steps of 0.613 mrad at 47.7 rev/s: 17.457 ms.
      EXPECT_NEAR(ev->scan.utime_last - ev->scan.utime_first, 17457, 1);
      if (prev_scan >= 0) {
        EXPECT_NEAR(ev->scan.utime_first - prev_scan, 1e6 / 47.7, 1.0);
      }
      prev_scan = ev->scan.utime_first;
      int valid = 0;
      for (float r : ev->scan.ranges) valid += r > 0.0f;
      EXPECT_GT(valid, 4000);  // indoors most of the ~300 deg answer
    } else if (ev->kind == SimEvent::Kind::kScanProfile) {
      EXPECT_EQ(ev->scan.ranges.size(), 8133u);
      EXPECT_NEAR(ev->scan.utime_last - ev->scan.utime_first, 33329, 2);
      for (float r : ev->scan.ranges) EXPECT_LE(r, 6.0f);
    }
  }
  EXPECT_NEAR(counts[0], 2.0 * 200, 1);
  EXPECT_NEAR(counts[1], 2.0 * 200, 1);
  EXPECT_NEAR(counts[2], 2.0 * 47.7, 1);
  EXPECT_NEAR(counts[3], 2.0 * 30, 1);
}

// Scan points placed with the ground truth at their own time and the rig's extrinsics lie on
// the world's true surfaces: checks the 3D geometry end to end (and distance_to_surface). A few
// are ghosts of beams mirrored by glass or steel.
TEST(Simulator, ScanPointsLieOnTheTrueSurfaces) {
  WorldSpec world_spec;
  load_config("configs/worlds/office.yaml", world_spec);
  RouteSpec route;
  load_config("configs/routes/office-s2.yaml", route);
  RunOptions run;
  run.begin_s = 20.0;
  run.duration_s = 0.2;
  const RigConfig rig;
  Simulator sim(world_spec, route, rig, PlatformConfig{}, 1, 0, run, Effects{}.ideal());
  int points = 0, on_surface = 0;
  while (auto ev = sim.next()) {
    if (ev->kind != SimEvent::Kind::kScanProfile && ev->kind != SimEvent::Kind::kScanHorizontal)
      continue;
    const Eigen::Isometry3d T_base_laser = ev->kind == SimEvent::Kind::kScanProfile
                                               ? rig.laser_profile.transform()
                                               : rig.laser_horizontal.transform();
    const ScanData& s = ev->scan;
    const int n = static_cast<int>(s.ranges.size());
    for (int i = 0; i < n; i += 7) {
      if (s.ranges[i] <= 0.0f) continue;
      const double t =
          1e-6 * (s.utime_first + (s.utime_last - s.utime_first) * double(i) / (n - 1));
      const Pose2 T_world_base = sim.trajectory().pose(t);
      const double a = s.angle_first + i * double(s.angle_step);
      const Eigen::Vector3d p_laser = s.ranges[i] * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
      const Eigen::Vector3d p_base = T_base_laser * p_laser;
      const Eigen::Vector2d xy = T_world_base * Eigen::Vector2d(p_base.head<2>());
      ++points;
      on_surface += sim.world().distance_to_surface({xy.x(), xy.y(), p_base.z()}, 0.5) < 0.01;
    }
  }
  EXPECT_GT(points, 5000);
  EXPECT_GT(on_surface, 0.98 * points);
}

}  // namespace
}  // namespace traverse::sim
