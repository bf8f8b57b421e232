// Guidance: the nearest key pose worse than each bottom level, with the run of consecutive key
// poses around it; the nearest well-localised key pose old enough to close a loop with.
#include "guidance.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace traverse::viewer {
namespace {

constexpr int64_t kS = 1'000'000;

Legend legend() {
  Legend l;
  for (const char* n : {"LOA30", "LOA20", "LOA10"}) l.levels.push_back({n, 0, 0, {}, true});
  l.best_level = 0;
  l.worst_level = 2;
  return l;
}

TEST(Guidance, FindsThePoorRegionAndTheLoopTarget) {
  // Key poses 0..9 along x, one metre and ten seconds apart: levels 0 0 1 1 2 2 2 1 0 0.
  const int levels[10] = {0, 0, 1, 1, 2, 2, 2, 1, 0, 0};
  std::map<int64_t, KeyAnnotation> keys;
  for (int i = 0; i < 10; ++i) {
    keys[i] = {.id = i, .utime = i * 10 * kS, .x = double(i), .y = 0.0, .level = levels[i]};
  }
  // The cart at x = 9.5, 2 m to the side, at t = 100 s.
  const StampedPose now{100 * kS, Pose2(9.5, 2.0, 0.0)};
  const Guidance g = guide(keys, legend(), now, 30.0);
  ASSERT_EQ(g.below.size(), 3u);
  // Worse than LOA30: the nearest is key 7 (level 1); its run is keys 2..7.
  ASSERT_TRUE(g.below[0]);
  EXPECT_EQ(g.below[0]->nearest.id, 7);
  EXPECT_NEAR(g.below[0]->nearest.distance_m, std::hypot(2.5, 2.0), 1e-9);
  EXPECT_EQ(g.below[0]->first_id, 2);
  EXPECT_EQ(g.below[0]->last_id, 7);
  EXPECT_EQ(g.below[0]->keys, 6);
  // Worse than LOA20: keys 4..6, nearest 6.
  ASSERT_TRUE(g.below[1]);
  EXPECT_EQ(g.below[1]->nearest.id, 6);
  EXPECT_EQ(g.below[1]->first_id, 4);
  EXPECT_EQ(g.below[1]->last_id, 6);
  // Nothing is worse than the last level.
  EXPECT_FALSE(g.below[2]);
  // Green keys 8 and 9 are nearer but younger than 30 s: the target is key 1 (t = 10 s).
  ASSERT_TRUE(g.loop_target);
  EXPECT_EQ(g.loop_target->id, 1);
  EXPECT_NEAR(g.loop_target->distance_m, std::hypot(8.5, 2.0), 1e-9);
  // Without the age limit the nearest green key pose is the target.
  EXPECT_EQ(guide(keys, legend(), now, 0.0).loop_target->id, 9);
}

TEST(Guidance, SaysNothingWithoutKeyPoses) {
  const Guidance g = guide({}, legend(), StampedPose{}, 30.0);
  for (const auto& r : g.below) EXPECT_FALSE(r);
  EXPECT_FALSE(g.loop_target);
}

}  // namespace
}  // namespace traverse::viewer
