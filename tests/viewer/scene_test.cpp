// The viewer's scene: preview profiles placed with the corrected trajectory at their time and
// moved (only) when a newer revision moves it; the drawn trajectory decimated; annotations kept by
// id and checked against the legend; the newest frontend pose carried onto the corrected
// trajectory; changes reported once.
#include "scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace traverse::viewer {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;

// Straight along x at 1 m/s from (x0, y), poses every 0.1 s over [t0, t1] seconds.
mapper::TrajectorySegment straight(int64_t key, double t0, double t1, double y,
                                   double theta = 0.0) {
  mapper::TrajectorySegment s;
  s.key_id_first = key;
  for (double t = t0; t <= t1 + 1e-9; t += 0.1) {
    s.utimes.push_back(kT0 + std::llround(t * 1e6));
    s.T_world_base.emplace_back(t, y, theta);
  }
  return s;
}

std::vector<std::array<int16_t, 3>> one_point(int16_t x_mm) { return {{x_mm, 0, 1500}}; }

Legend three_levels() {
  Legend l;
  l.standard = "USIBD LOA";
  l.levels = {{"LOA30", 0.005, 0.015, {0, 200, 0}, true},
              {"LOA20", 0.015, 0.05, {230, 230, 0}, true},
              {"LOA10", 0.05, INFINITY, {230, 0, 0}, true}};
  l.best_level = 0;
  l.worst_level = 2;
  return l;
}

TEST(Scene, PlacesProfilesWhenTheTrajectoryCoversThem) {
  Scene scene({});
  scene.add_profile(kT0 + 500'000, one_point(1000));  // before any trajectory: waits
  EXPECT_TRUE(scene.take_changes().new_profiles.empty());
  scene.set_segment(straight(0, 0.0, 1.0, 2.0), 0);
  Changes c = scene.take_changes();
  ASSERT_EQ(c.new_profiles.size(), 1u);
  const Profile& p = scene.profiles()[c.new_profiles[0]];
  EXPECT_TRUE(p.placed);
  EXPECT_NEAR(p.T_map_base.x(), 0.5, 1e-9);  // interpolated at the profile's time
  EXPECT_NEAR(p.T_map_base.y(), 2.0, 1e-9);
  EXPECT_EQ(c.segments, std::vector<int64_t>{0});
  // A profile inside the trajectory is placed at once; nothing is reported twice.
  scene.add_profile(kT0 + 800'000, one_point(1000));
  c = scene.take_changes();
  EXPECT_EQ(c.new_profiles.size(), 1u);
  EXPECT_TRUE(c.moved_profiles.empty());
  EXPECT_TRUE(scene.take_changes().empty());
  EXPECT_EQ(scene.points(), 2);
}

TEST(Scene, MovesProfilesOnlyWithANewerRevision) {
  Scene scene({});
  scene.set_segment(straight(0, 0.0, 1.0, 0.0), 0);
  scene.set_segment(straight(10, 1.0, 2.0, 0.0), 0);
  scene.add_profile(kT0 + 300'000, one_point(100));
  scene.add_profile(kT0 + 1'500'000, one_point(100));
  scene.take_changes();
  // A loop closure moves the first segment by 0.2 m and turns it: only its profile moves.
  scene.set_segment(straight(0, 0.0, 1.0, 0.2, 0.1), 1);
  Changes c = scene.take_changes();
  ASSERT_EQ(c.moved_profiles.size(), 1u);
  EXPECT_EQ(scene.profiles()[c.moved_profiles[0]].utime, kT0 + 300'000);
  EXPECT_NEAR(scene.profiles()[c.moved_profiles[0]].T_map_base.y(), 0.2, 1e-9);
  EXPECT_NEAR(scene.profiles()[c.moved_profiles[0]].T_map_base.theta(), 0.1, 1e-9);
  // An older or equal revision arriving late is dropped and counted.
  scene.set_segment(straight(0, 0.0, 1.0, 0.0), 1);
  EXPECT_TRUE(scene.take_changes().moved_profiles.empty());
  EXPECT_EQ(scene.counters().segments_stale, 1);
  // The same poses again move nothing.
  scene.set_segment(straight(0, 0.0, 1.0, 0.2, 0.1), 2);
  EXPECT_TRUE(scene.take_changes().moved_profiles.empty());
}

TEST(Scene, KeepsTheRestOfASplitProfileButNotACopy) {
  Scene scene({});
  scene.set_segment(straight(0, 0.0, 1.0, 0.0), 0);
  scene.add_profile(kT0 + 500'000, {{1, 0, 0}, {2, 0, 0}});
  scene.add_profile(kT0 + 500'000, {{3, 0, 0}});  // the rest of the profile, in a second message
  EXPECT_EQ(scene.points(), 3);
  scene.add_profile(kT0 + 500'000, {{1, 0, 0}, {2, 0, 0}});  // sent again to a late viewer
  scene.add_profile(kT0 + 500'000, {{3, 0, 0}});
  EXPECT_EQ(scene.points(), 3);
  EXPECT_EQ(scene.profiles().size(), 1u);
  EXPECT_EQ(scene.profiles()[0].p_base_mm.size(), 3u);
  EXPECT_EQ(scene.counters().profiles_repeated, 2);
}

TEST(Scene, RejectsWhatCannotBeUsed) {
  Scene scene({.trajectory_step_m = 0.05, .pose_history_s = 60, .max_points = 3});
  mapper::TrajectorySegment bad = straight(0, 0.0, 1.0, 0.0);
  std::swap(bad.utimes[1], bad.utimes[2]);
  scene.set_segment(bad, 0);
  EXPECT_EQ(scene.counters().segments_rejected, 1);
  scene.add_profile(kT0, {});
  EXPECT_EQ(scene.counters().profiles_rejected, 1);
  scene.add_profile(kT0 + 1, {{1, 1, 1}, {2, 2, 2}});
  scene.add_profile(kT0 + 2, {{1, 1, 1}, {2, 2, 2}});  // one point fits under max_points
  EXPECT_EQ(scene.points(), 3);
  EXPECT_EQ(scene.counters().points_dropped, 1);
  scene.add_profile(kT0 + 3, one_point(5));
  EXPECT_EQ(scene.counters().profiles_rejected, 2);

  KeyAnnotation k{.id = 1, .utime = kT0, .x = 0, .y = 0, .bound_m = 0.01, .level = 3};
  scene.set_annotations(three_levels(), {k});  // level 3 of three: rejected
  EXPECT_EQ(scene.counters().annotations_rejected, 1);
  scene.set_annotations(Legend{}, {k});  // no legend
  EXPECT_EQ(scene.counters().annotations_rejected, 2);
  k.level = 2;
  scene.set_annotations(three_levels(), {k});
  EXPECT_EQ(scene.annotations().size(), 1u);
  const Changes c = scene.take_changes();
  EXPECT_TRUE(c.legend);
  EXPECT_EQ(c.annotations, std::vector<int64_t>{1});
  scene.set_annotations(three_levels(), {k});
  EXPECT_FALSE(scene.take_changes().legend);  // the same legend again is no change
}

TEST(Scene, DrawsTheTrajectoryDecimated) {
  Scene scene({.trajectory_step_m = 0.25, .pose_history_s = 60, .max_points = 10});
  scene.set_segment(straight(0, 0.0, 1.0, 0.0), 0);  // 11 poses 0.1 m apart
  const Polyline& p = scene.polylines().at(0);
  ASSERT_EQ(p.xy.size(), 5u);  // 0, 0.3, 0.6, 0.9 and the last, 1.0
  EXPECT_NEAR(p.xy[1][0], 0.3, 1e-6);
  EXPECT_NEAR(p.xy.back()[0], 1.0, 1e-6);
}

TEST(Scene, CarriesTheNewestPoseOntoTheCorrectedTrajectory) {
  Scene scene({});
  EXPECT_FALSE(scene.current_pose());
  // The frontend drives along x; the corrected trajectory (a loop closure) says it was 0.5 m to
  // the left and turned by 90 degrees at t = 1 s.
  for (int i = 0; i <= 30; ++i) {
    scene.set_frontend_pose(kT0 + i * 100'000, Pose2(0.1 * i, 0.0, 0.0));
  }
  EXPECT_NEAR(scene.current_pose()->T_map_base.x(), 3.0, 1e-9);  // no trajectory yet: frontend
  mapper::TrajectorySegment s = straight(0, 0.0, 1.0, 0.0);
  for (auto& T : s.T_world_base) T = Pose2(0.0, 0.5 + T.x(), std::numbers::pi / 2);
  scene.set_segment(s, 0);
  const auto now = scene.current_pose();
  ASSERT_TRUE(now);
  EXPECT_EQ(now->utime, kT0 + 3'000'000);
  // 2 m further along the frontend's x is 2 m along the corrected heading (+y).
  EXPECT_NEAR(now->T_map_base.x(), 0.0, 1e-9);
  EXPECT_NEAR(now->T_map_base.y(), 3.5, 1e-9);
  EXPECT_NEAR(now->T_map_base.theta(), std::numbers::pi / 2, 1e-9);
}

}  // namespace
}  // namespace traverse::viewer
