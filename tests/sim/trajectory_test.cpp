#include "trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "config.hpp"
#include "simulator.hpp"
#include "world.hpp"

namespace traverse::sim {
namespace {

const char* const kRoutes[] = {"office-x1",       "office-x2",    "office-s1",
                               "office-s2",       "office-s3",    "court-loop",
                               "corridor-return", "office-rooms", "lab-loop"};

RouteSpec load_route(const std::string& name) {
  RouteSpec r;
  load_config("configs/routes/" + name + ".yaml", r);
  return r;
}

TEST(Trapezoid, ReachesTheAmountAndIsContinuous) {
  for (const double amount : {0.05, 1.0, 10.0}) {
    const double T = trapezoid_duration(amount, 0.5, 0.4);
    double s, v;
    trapezoid_at(amount, 0.5, 0.4, T, s, v);
    EXPECT_NEAR(s, amount, 1e-12);
    EXPECT_NEAR(v, 0.0, 1e-12);
    double prev = 0.0;
    for (double t = 0.0; t <= T; t += 1e-3) {
      trapezoid_at(amount, 0.5, 0.4, t, s, v);
      EXPECT_LE(v, 0.5 + 1e-12);
      EXPECT_LE(s - prev, 0.5 * 1e-3 + 1e-9);
      EXPECT_GE(s, prev - 1e-12);
      prev = s;
    }
  }
}

TEST(Routes, OfficeRoutesHaveThePapersLengthsSpeedsAndScanners) {
  PlatformConfig platform;
  for (const char* name : {"office-x1", "office-x2", "office-s1", "office-s2", "office-s3"}) {
    const RouteSpec r = load_route(name);
    Rng rng(1);
    const Trajectory traj(r, platform, rng, Effects{}.ideal());
    EXPECT_EQ(r.world, "office") << name;
    EXPECT_GE(traj.length_m(), 230.0) << name;
    EXPECT_LE(traj.length_m(), 310.0) << name;
    const bool x = std::string(name).find("-x") != std::string::npos;
    EXPECT_EQ(r.horizontal_scanner, x ? "focus3d_x330" : "focus3d_120s") << name;
    // Average speed over the whole run, stops and turns included (Table 1: 0.25-0.52 m/s).
    const double mean = traj.length_m() / traj.duration_s();
    EXPECT_GT(mean, x ? 0.2 : 0.4) << name;
    EXPECT_LT(mean, x ? 0.3 : 0.55) << name;
  }
}

// The cart (about 0.6 m wide) never touches anything between the floor and 1.2 m.
TEST(Routes, StayInFreeSpace) {
  // Both profiles: the ideal cart stopping and turning in the ideal world, and the pushed cart
  // (arcs, weave, detours into the bare corridor) in the realistic world with every movable.
  PlatformConfig platform;
  const Effects realistic;
  for (const Effects& fx : {realistic.ideal(), realistic}) {
    for (const char* name : kRoutes) {
      const RouteSpec r = load_route(name);
      WorldSpec spec;
      load_config("configs/worlds/" + r.world + ".yaml", spec);
      Rng rng(1);
      const Trajectory traj(r, platform, rng, fx);
      // The world of the profile's layers, with movables where they are at each moment.
      WorldOptions opt;
      opt.layers = fx.world_layers;
      if (fx.world_changes.enabled)
        opt.swap_times = movable_swap_times(spec, traj, fx.world_changes.visit_radius_m);
      const World world(spec, 0.5, opt);
      double worst = 1e9;
      for (double t = 0.0; t <= traj.duration_s(); t += 0.1) {
        const Pose2 p = traj.pose(t);
        worst = std::min(worst, world.clearance_2d(p.translation(), 0.02, 1.2, t));
      }
      EXPECT_GE(worst, 0.4) << name << (fx.motion.enabled ? " realistic" : " ideal");
    }
  }
}

TEST(Trajectory, GroundTruthIsContinuousAndStartsAndEndsAtRest) {
  PlatformConfig platform;
  const RouteSpec r = load_route("office-s2");
  Rng rng(1);
  const Trajectory traj(r, platform, rng, Effects{}.ideal());
  const double dt = 1e-3;
  Pose2 prev = traj.pose(0.0);
  double max_step = 0.0, max_turn = 0.0;
  for (double t = dt; t <= traj.duration_s(); t += dt) {
    const Pose2 p = traj.pose(t);
    max_step = std::max(max_step, (p.translation() - prev.translation()).norm());
    max_turn = std::max(max_turn, std::abs(wrap_angle(p.theta() - prev.theta())));
    prev = p;
  }
  // Cruise speed plus vibration (a few mm at up to ~10 Hz) per millisecond.
  EXPECT_LT(max_step, (r.speed_mps + 0.1) * dt);
  EXPECT_LT(max_turn, (platform.yaw_rate_radps + 0.1) * dt);
  // Standing still at the start: the pose does not move (no vibration without motion).
  EXPECT_NEAR((traj.pose(0.0).translation() - traj.pose(1.5).translation()).norm(), 0.0, 1e-12);
  const Pose2 end = traj.pose(traj.duration_s());
  EXPECT_NEAR(end.x(), r.waypoints.back()[0], 1e-9);
  EXPECT_NEAR(end.y(), r.waypoints.back()[1], 1e-9);
}

TEST(Trajectory, VibratesByAFewMillimetresAroundTheNominalPath) {
  PlatformConfig platform;
  const RouteSpec r = load_route("corridor-return");
  Rng rng(3);
  const Trajectory traj(r, platform, rng, Effects{}.ideal());
  double max_offset = 0.0, max_yaw = 0.0;
  for (double t = 0.0; t <= traj.duration_s(); t += 0.01) {
    const Pose2 d = between(traj.nominal_pose(t), traj.pose(t));
    max_offset = std::max(max_offset, d.translation().norm());
    max_yaw = std::max(max_yaw, std::abs(d.theta()));
  }
  EXPECT_GT(max_offset, 0.001);
  EXPECT_LT(max_offset, 0.006);
  EXPECT_GT(max_yaw, 0.001);
  EXPECT_LT(max_yaw, 0.006);
}

}  // namespace
}  // namespace traverse::sim
