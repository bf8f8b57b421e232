// The frontend with wheel odometry as its motion prior (motion_prior.hpp): a sharp turn during a
// pause in the scanner's stream, and odometry that stops part way (the fallback, counted).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "frontend.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

using testing::kPeriodUs;
using testing::small_sweep;

// A cart in the room: 0.5 m/s turning 0.3 rad/s for 1 s; then the scanner pauses 1 s (a sparse
// scan) while the cart goes 4 m and turns 1.5 rad; then on as before. The step across the
// pause lies beyond the wide search's window (matcher.wide_search_linear_window_m, 2 m) around
// what the poses' velocity predicts.
Pose2 truth_room(int64_t t) {
  const double s = 1e-6 * static_cast<double>(t);
  const double a = std::min(s, 1.0), b = std::clamp(s - 1.0, 0.0, 1.0), c = std::max(0.0, s - 2.0);
  return Pose2(-2.0, -1.0, 0.0) * Pose2::exp(Eigen::Vector3d(0.5, 0.0, 0.3) * a) *
         Pose2::exp(Eigen::Vector3d(4.0, 0.0, 1.5) * b) *
         Pose2::exp(Eigen::Vector3d(0.5, 0.0, 0.3) * c);
}

struct RoomRun {
  double max_position_error_m = 0.0, max_heading_error_rad = 0.0;
  std::map<std::string, double> counters;
};

// odometry_until_s: odometry is published until then (0: none at all).
RoomRun run_room(double odometry_until_s) {
  const auto world = synthetic::room();
  const auto frontend = make_frontend(FrontendConfig{});
  std::mt19937 rng(5);
  RoomRun run;
  int64_t odometry_t = 0;
  Pose2 T_map_world;
  std::vector<int64_t> starts;
  for (int64_t t = 0; t < 1'000'000; t += kPeriodUs) starts.push_back(t);
  for (int64_t t = 2'000'000; t < 2'600'000; t += kPeriodUs) starts.push_back(t);
  for (const int64_t t0 : starts) {
    const Scan scan = synthetic::make_sweep(world, truth_room, Pose2(), small_sweep(t0), &rng);
    for (;
         odometry_t <= scan.utime_last && 1e-6 * static_cast<double>(odometry_t) < odometry_until_s;
         odometry_t += 20'000) {
      OdometrySample o;
      o.utime = odometry_t;
      // Wheels 1 % long (an uncalibrated radius) and the heading 2 % short: good, not exact.
      const Eigen::Vector3d xi = (Pose2(-2.0, -1.0, 0.0).inverse() * truth_room(odometry_t)).log();
      o.T_odom_base = Pose2(7.0, 3.0, -1.0) *
                      Pose2::exp(Eigen::Vector3d(1.01 * xi.x(), 1.01 * xi.y(), 0.98 * xi.z()));
      EXPECT_TRUE(frontend->add_odometry(o));
    }
    const FrontendResult r = frontend->process(scan);
    if (t0 == 0) T_map_world = r.T_map_base * truth_room(scan.utime_last).inverse();
    const Pose2 T_true = T_map_world * truth_room(scan.utime_last);
    run.max_position_error_m = std::max(run.max_position_error_m,
                                        (r.T_map_base.translation() - T_true.translation()).norm());
    run.max_heading_error_rad = std::max(
        run.max_heading_error_rad, std::abs(wrap_angle(r.T_map_base.theta() - T_true.theta())));
  }
  run.counters = testing::counters_of(*frontend);
  return run;
}

// The scan after the pause is sparse: the wide search, centred on odometry's prediction and sized
// by its covariance, finds it; without odometry the frontend is printed for comparison.
TEST(FrontendOdometry, OdometryCarriesTheStepAcrossAPause) {
  const RoomRun with = run_room(100.0);
  const RoomRun without = run_room(0.0);
  std::printf("room with a 1 s pause, largest error [m, rad]: odometry %.4f %.4f, none %.4f %.4f\n",
              with.max_position_error_m, with.max_heading_error_rad, without.max_position_error_m,
              without.max_heading_error_rad);
  EXPECT_LT(with.max_position_error_m, 0.1);
  EXPECT_LT(with.max_heading_error_rad, 0.03);
  EXPECT_GT(without.max_position_error_m, 1.0);
  EXPECT_GT(with.counters.at("odometry_predictions"), 70);
  EXPECT_EQ(without.counters.at("odometry_predictions"), 0);
  EXPECT_EQ(without.counters.at("odometry_stale"), 0);  // a rig without odometry lacks nothing
}

// Odometry that stops publishing (at 0.5 s): the scans after are predicted without it, each
// counted stale, and the frontend goes on.
TEST(FrontendOdometry, OdometryThatStopsFallsBackAndIsCounted) {
  const RoomRun run = run_room(0.5);
  EXPECT_GT(run.counters.at("odometry_stale"), 40);
  EXPECT_GT(run.counters.at("odometry_predictions"), 20);
  EXPECT_EQ(run.counters.at("scans_dropped_time"), 0);
}

// Turning almost in place in the room (0.6 rad/s) with odometry, one scan taken 0.5 s (0.3 rad)
// before its stamp, as a logger that stamps on arrival leaves some (intel). Its pose is where it
// was taken, it is counted, and the motion goes on from the odometry at its stamp: the poses
// after it stay on the truth. Taken as the pose at its stamp, it turns the trajectory back 0.3
// rad and the next scans' predictions with it.
TEST(FrontendOdometry, AScanStampedLateKeepsItsPoseAndNotTheMotion) {
  const auto truth = [](int64_t t) {
    return Pose2(-1.0, 0.5, 0.2) *
           Pose2::exp(Eigen::Vector3d(0.05, 0.0, 0.6) * (1e-6 * static_cast<double>(t)));
  };
  constexpr int64_t kLateUs = 500'000;
  constexpr int kLateScan = 60;  // at 1.26 s
  const auto world = synthetic::room();
  const auto frontend = make_frontend(FrontendConfig{});
  std::mt19937 rng(7);
  int64_t odometry_t = 0;
  Pose2 T_map_world;
  double max_position_error_m = 0.0, max_heading_error_rad = 0.0, late_heading_error_rad = 1.0;
  for (int k = 0; k < 120; ++k) {
    const int64_t t0 = k * kPeriodUs;
    const bool late = k == kLateScan;
    Scan scan = synthetic::make_sweep(world, truth, Pose2(), small_sweep(late ? t0 - kLateUs : t0),
                                      &rng);
    if (late) {
      scan.utime_first += kLateUs;
      scan.utime_last += kLateUs;
    }
    for (; odometry_t <= scan.utime_last; odometry_t += 20'000) {
      OdometrySample o;
      o.utime = odometry_t;
      o.T_odom_base = Pose2(3.0, 1.0, 0.5) * truth(odometry_t);
      ASSERT_TRUE(frontend->add_odometry(o));
    }
    const FrontendResult r = frontend->process(scan);
    if (k == 0) T_map_world = r.T_map_base * truth(scan.utime_last).inverse();
    const Pose2 T_true = T_map_world * truth(scan.utime_last - (late ? kLateUs : 0));
    const double heading_error = std::abs(wrap_angle(r.T_map_base.theta() - T_true.theta()));
    if (late) {
      late_heading_error_rad = heading_error;
      continue;
    }
    max_position_error_m = std::max(max_position_error_m,
                                    (r.T_map_base.translation() - T_true.translation()).norm());
    max_heading_error_rad = std::max(max_heading_error_rad, heading_error);
  }
  const auto counters = testing::counters_of(*frontend);
  std::printf("late scan: its heading %.4f rad from where it was taken; the others at most %.4f m "
              "%.4f rad off\n",
              late_heading_error_rad, max_position_error_m, max_heading_error_rad);
  EXPECT_EQ(counters.at("scans_late"), 1);
  EXPECT_LT(late_heading_error_rad, 0.01);
  EXPECT_LT(max_position_error_m, 0.02);
  EXPECT_LT(max_heading_error_rad, 0.01);
}

}  // namespace
}  // namespace traverse::frontend
