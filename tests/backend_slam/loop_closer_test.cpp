#include "loop_closer.hpp"

#include <gtest/gtest.h>

#include "synthetic.hpp"

namespace traverse::backend {
namespace {

using test::synthetic::World;
constexpr double kRange = 5.0;  // [m] short range: farther candidates overlap the chain less

// An old chain of key scans along the corridor at x = 0 .. 6 m (or from 0.5 * chain_first_step)
// (estimates = truth), then current
// key scans at true x positions `current_x`, estimated with a common drift error, then one far
// away that ends the episode. Returns the closures and the closer's counters.
struct ClosureRun {
  std::vector<LoopClosure> closures;
  LoopCloserCounters counters;
  std::vector<Pose2> truth;
  int first_current = 0;
};

ClosureRun run(const World& world, const std::vector<double>& current_x, const Pose2& drift,
               int chain_first_step = 0, LoopCloserConfig config = {}) {
  std::mt19937 rng(3);
  ScanStore scans;
  ClosureRun r;
  std::vector<Pose2> poses;
  std::vector<double> travel;
  for (int i = chain_first_step; i <= 12; ++i) {
    r.truth.emplace_back(0.5 * i, 0.1, 0.0);
    poses.push_back(r.truth.back());
    travel.push_back(0.5 * (i - chain_first_step));
  }
  r.first_current = static_cast<int>(poses.size());
  std::vector<double> xs = current_x;
  xs.push_back(13.0);  // far from the chain: the episode ends here
  for (double x : xs) {
    r.truth.emplace_back(x, -0.2, M_PI);  // coming back the other way
    poses.push_back(r.truth.back() * drift);
    travel.push_back(40.0 + 14.0 - x);
  }
  for (const Pose2& T : r.truth) scans.add(test::key_points(world, T, kRange, rng));

  config.coarse.max_query_points = 300;
  LoopCloser closer(config);
  for (int i = r.first_current; i < static_cast<int>(poses.size()); ++i) {
    const std::vector<Pose2> known(poses.begin(), poses.begin() + i + 1);
    if (auto c = closer.add(i, known, travel, scans)) r.closures.push_back(*c);
  }
  r.counters = closer.counters();
  return r;
}

TEST(LoopCloser, ClosesWithTheBestOfAllNearbyCandidates) {
  const Pose2 drift(0.35, -0.25, 0.06);
  const ClosureRun r = run(test::irregular_corridor(), {8.2, 7.6, 7.0, 6.4}, drift);
  ASSERT_EQ(r.closures.size(), 1u);
  const LoopClosure& c = r.closures[0];
  // The closest candidate (x = 6.4, the last one) overlaps the chain most.
  EXPECT_EQ(c.to, r.first_current + 3);
  EXPECT_EQ(c.candidates_tried, 4);
  EXPECT_EQ(r.counters.candidates, 4);
  // The measurement agrees with the truth, within a few standard deviations.
  const Pose2 T_true = between(r.truth[c.from], r.truth[c.to]);
  const Eigen::Vector2d dt = T_true.translation() - c.T_from_to.translation();
  EXPECT_LT(dt.norm(), 0.03);
  EXPECT_LT(std::abs(wrap_angle(T_true.theta() - c.T_from_to.theta())), 0.005);
  EXPECT_GT(c.response, 0.6);
}

TEST(LoopCloser, RejectsAClosureInARepetitiveScene) {
  // Identical niches every 1.5 m along an old chain from x = -6 to 6 m. The platform is really at
  // x = 9.7 .. 8.5 m but has drifted 9 m (six periods), so its scans fit the chain at its
  // estimate, and a period either side, as well as anywhere: a closure would be false. The
  // ambiguity check must refuse to close.
  const ClosureRun r =
      run(test::repetitive_corridor(), {9.7, 9.3, 8.9, 8.5}, Pose2(9.0, 0.0, 0.0), -12);
  EXPECT_TRUE(r.closures.empty());
  EXPECT_GE(r.counters.rejected_ambiguous, 1);
  EXPECT_EQ(r.counters.closures, 0);
}

TEST(LoopCloser, NoEpisodeWithoutOldKeyPosesNearby) {
  // Current scans far from the chain: nothing tried.
  const ClosureRun r = run(test::irregular_corridor(), {12.0, 11.5}, Pose2());
  EXPECT_TRUE(r.closures.empty());
  EXPECT_EQ(r.counters.candidates, 0);
}

// A corridor bare but for one shallow niche: the refinement's information along the axis is a
// small share of the rest. Opened (degeneracy_min_ratio), the closure's covariance along the axis
// is what its information allows, not the correlative surface's centimetres; across it nothing
// changes. (The ambiguity check is off here, to reach the covariance: on intel such closures
// pass it.)
TEST(LoopCloser, AClosureAlongAnAlmostBareCorridorIsOpenedAlongItsAxis) {
  World world = test::synthetic::corridor(60.0, 2.4);
  world.push_back({{3.0, 1.2}, {3.0, 1.25}});  // a niche 5 cm deep in the north wall
  world.push_back({{3.0, 1.25}, {3.4, 1.25}});
  world.push_back({{3.4, 1.25}, {3.4, 1.2}});
  const Pose2 drift(0.2, 0.0, 0.0);
  std::vector<ClosureRun> runs;
  for (const double ratio : {0.0, 0.01}) {
    LoopCloserConfig config;
    config.degeneracy_min_ratio = ratio;
    config.max_ambiguity_ratio = 1.0;
    runs.push_back(run(world, {5.6, 5.2, 4.8, 4.4}, drift, 0, config));
  }
  ASSERT_EQ(runs[0].closures.size(), 1u);
  ASSERT_EQ(runs[1].closures.size(), 1u);
  EXPECT_EQ(runs[0].counters.opened, 0);
  EXPECT_EQ(runs[1].counters.opened, 1);
  const Eigen::Matrix3d& plain = runs[0].closures[0].covariance;
  const Eigen::Matrix3d& opened = runs[1].closures[0].covariance;
  // The corridor's axis is x in the world and, coming back, in the closure's frame too.
  EXPECT_GT(std::sqrt(opened(0, 0)), 1.5 * std::sqrt(plain(0, 0)));
  EXPECT_NEAR(std::sqrt(opened(1, 1)), std::sqrt(plain(1, 1)), 0.01 * std::sqrt(plain(1, 1)));
}

}  // namespace
}  // namespace traverse::backend
