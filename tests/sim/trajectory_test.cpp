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
      const Trajectory traj(r, platform, rng, fx, draw_start_yaw(fx.motion, Rng(1, 15)));
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

// Set down turned from its first leg, the pushed cart starts with that heading where it was set
// down and rolls back onto the very path it would have taken, at the same times, within
// start_settle_m.
TEST(Trajectory, APushedCartSetDownTurnedRollsBackOntoItsLine) {
  PlatformConfig platform;
  const Effects realistic;
  const RouteSpec r = load_route("office-s2");
  const double yaw = 0.03;
  Rng rng_square(1), rng_turned(1);
  const Trajectory square(r, platform, rng_square, realistic, 0.0);
  const Trajectory turned(r, platform, rng_turned, realistic, yaw);
  ASSERT_DOUBLE_EQ(square.duration_s(), turned.duration_s());
  EXPECT_NEAR(wrap_angle(turned.nominal_pose(0.0).theta() - square.nominal_pose(0.0).theta()),
              yaw, 1e-9);
  EXPECT_NEAR((turned.nominal_pose(0.0).translation() - square.nominal_pose(0.0).translation())
                  .norm(),
              0.0, 1e-12);
  // Where the cart has rolled start_settle_m along its line, the two are one path.
  const double settle = realistic.motion.start_settle_m;
  double worst_lateral = 0.0, t_settled = -1.0;
  for (double t = 0.0; t <= square.duration_s(); t += 0.01) {
    const Pose2 a = square.nominal_pose(t), b = turned.nominal_pose(t);
    const double apart = (a.translation() - b.translation()).norm();
    const double travelled = (a.translation() - square.nominal_pose(0.0).translation()).norm();
    if (travelled < settle - 0.05) {
      worst_lateral = std::max(worst_lateral, apart);
      // The heading turns back towards the line's as the cart rolls on.
      if (travelled > 0.5 * settle) {
        EXPECT_LT(std::abs(wrap_angle(b.theta() - a.theta())), yaw);
      }
    } else if (travelled > settle + 0.05) {
      if (t_settled < 0.0) t_settled = t;
      EXPECT_NEAR(apart, 0.0, 1e-9) << "t " << t;
      EXPECT_NEAR(wrap_angle(b.theta() - a.theta()), 0.0, 1e-9) << "t " << t;
    }
  }
  ASSERT_GT(t_settled, 0.0);
  // y = tan(yaw) s (1 - s / L)^2 is largest at s = L / 3: 4 / 27 L tan(yaw), 8.9 mm here.
  EXPECT_GT(worst_lateral, 0.5 * 4.0 / 27.0 * settle * std::tan(yaw));
  EXPECT_LT(worst_lateral, 1.01 * 4.0 / 27.0 * settle * std::tan(yaw));
}

TEST(Trajectory, StartYawsAreDrawnInTheirRangeWithBothSigns) {
  const Effects realistic;
  const MotionEffect& m = realistic.motion;
  int positive = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    const double yaw = draw_start_yaw(m, Rng(seed, 15));
    EXPECT_GE(std::abs(yaw), m.start_yaw_min_rad);
    EXPECT_LE(std::abs(yaw), m.start_yaw_max_rad);
    positive += yaw > 0.0;
  }
  EXPECT_GT(positive, 70);
  EXPECT_LT(positive, 130);
  EXPECT_EQ(draw_start_yaw(realistic.ideal().motion, Rng(1, 15)), 0.0);
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
