#include "correlative_matcher.hpp"

#include <gtest/gtest.h>

#include "synthetic.hpp"

namespace traverse::backend {
namespace {

using test::synthetic::World;

// Reference scan at the origin; the query is taken at T_true and searched from T_true with an
// error.
struct Case {
  World world;
  Pose2 T_world_true;
  Pose2 guess_error;
};

MatchResult run(const Case& c, const CorrelativeMatcherConfig& config) {
  std::mt19937 rng(7);
  std::vector<Eigen::Vector2d> reference;
  for (const auto& p : test::key_points(c.world, Pose2(), 20.0, rng)) {
    reference.push_back(p.cast<double>());
  }
  const auto query = test::to_double(test::key_points(c.world, c.T_world_true, 20.0, rng));
  return CorrelativeMatcher(config).match(reference, query, c.T_world_true * c.guess_error);
}

CorrelativeMatcherConfig wide() {
  CorrelativeMatcherConfig config;
  config.linear_window_m = 0.4;
  config.angular_window_rad = 0.15;
  config.penalty_sigma_xy_m = 10.0;  // practically no penalty
  config.penalty_sigma_theta_rad = 10.0;
  return config;
}

TEST(CorrelativeMatcher, RecoversAKnownOffset) {
  for (const Pose2& error : {Pose2(0.21, -0.13, 0.07), Pose2(-0.3, 0.25, -0.1), Pose2()}) {
    const Case c{test::synthetic::room(), Pose2(0.8, 0.5, 0.3), error};
    const MatchResult m = run(c, wide());
    ASSERT_TRUE(m.valid);
    EXPECT_LT((m.T_world_query.translation() - c.T_world_true.translation()).norm(), 0.03);
    EXPECT_LT(std::abs(wrap_angle(m.T_world_query.theta() - c.T_world_true.theta())), 0.006);
    EXPECT_GT(m.raw_response, 0.75);
    EXPECT_LT(std::sqrt(m.covariance(0, 0)), 0.03);
    EXPECT_LT(std::sqrt(m.covariance(1, 1)), 0.03);
  }
}

TEST(CorrelativeMatcher, MultiResolutionSearchEqualsTheExhaustiveOne) {
  // coarse_factor 1 makes every block one pose: the search is exhaustive.
  const Case c{test::synthetic::room(), Pose2(-1.0, 0.4, -0.5), Pose2(0.1, 0.12, 0.04)};
  CorrelativeMatcherConfig exhaustive = wide();
  exhaustive.coarse_factor = 1;
  const MatchResult a = run(c, wide()), b = run(c, exhaustive);
  EXPECT_DOUBLE_EQ(a.response, b.response);
  EXPECT_LT(a.evaluations, b.evaluations / 4);  // and it expanded far fewer poses
}

TEST(CorrelativeMatcher, CovarianceIsWideAlongACorridorAndNarrowAcross) {
  // Two parallel walls along x: nothing fixes x.
  const Case c{test::synthetic::corridor(60.0, 2.4), Pose2(0.0, 0.3, 0.0), Pose2(0.1, 0.05, 0.02)};
  const MatchResult m = run(c, wide());
  ASSERT_TRUE(m.valid);
  EXPECT_LT(std::abs(m.T_world_query.y() - 0.3), 0.03);  // across: found
  EXPECT_GT(m.covariance(0, 0), 25.0 * m.covariance(1, 1));
  EXPECT_GT(std::sqrt(m.covariance(0, 0)), 0.1);  // [m] along: spread over the window
}

TEST(CorrelativeMatcher, PenaltyPullsAnUnconstrainedMatchToTheGuess) {
  // Along a corridor every x fits equally; a strong penalty keeps the guess (seed 000's setting).
  CorrelativeMatcherConfig config = wide();
  config.penalty_sigma_xy_m = 0.05;
  const Case c{test::synthetic::corridor(60.0, 2.4), Pose2(), Pose2(0.25, 0.0, 0.0)};
  const MatchResult m = run(c, config);
  EXPECT_NEAR(m.T_world_query.x(), 0.25, 0.031);
}

TEST(CorrelativeMatcher, SecondPeakAboveAShareIsFoundWithLessWork) {
  // Along a corridor a pose 0.3 m away fits almost as well as the best: the second peak is high.
  std::mt19937 rng(7);
  const World world = test::synthetic::corridor(60.0, 2.4);
  std::vector<Eigen::Vector2d> reference;
  for (const auto& p : test::key_points(world, Pose2(), 20.0, rng)) {
    reference.push_back(p.cast<double>());
  }
  const auto query = test::to_double(test::key_points(world, Pose2(0.0, 0.3, 0.0), 20.0, rng));
  const CorrelativeMatcher matcher(wide());
  const Pose2 guess(0.1, 0.35, 0.02);
  const MatchResult all = matcher.match(reference, query, guess, 0.3);
  ASSERT_TRUE(all.valid);
  const double share = all.second_peak_response / all.raw_response;
  EXPECT_GT(share, 0.85);
  // Asked only above a share below it: the same peak; above it: none.
  const MatchResult below = matcher.match(reference, query, guess, 0.3, share - 0.05);
  EXPECT_DOUBLE_EQ(below.second_peak_response, all.second_peak_response);
  const MatchResult above = matcher.match(reference, query, guess, 0.3, share + 0.01);
  EXPECT_EQ(above.second_peak_response, 0.0);
  // In a room the second peak is low: a floor at 85 % of the peak skips most of the search.
  const Case room{test::synthetic::room(), Pose2(0.8, 0.5, 0.3), Pose2(0.2, -0.1, 0.05)};
  std::vector<Eigen::Vector2d> room_reference;
  for (const auto& p : test::key_points(room.world, Pose2(), 20.0, rng)) {
    room_reference.push_back(p.cast<double>());
  }
  const auto room_query =
      test::to_double(test::key_points(room.world, room.T_world_true, 20.0, rng));
  const Pose2 room_guess = room.T_world_true * room.guess_error;
  const MatchResult room_all = matcher.match(room_reference, room_query, room_guess, 0.3);
  const MatchResult room_floor = matcher.match(room_reference, room_query, room_guess, 0.3, 0.85);
  EXPECT_LT(room_all.second_peak_response, 0.85 * room_all.raw_response);
  EXPECT_EQ(room_floor.second_peak_response, 0.0);
  EXPECT_LT(room_floor.evaluations, room_all.evaluations);
  EXPECT_EQ(room_floor.T_world_query.vector(), room_all.T_world_query.vector());
}

TEST(CorrelativeMatcher, EmptyInputIsInvalid) {
  const CorrelativeMatcher matcher{CorrelativeMatcherConfig{}};
  EXPECT_FALSE(matcher.match({}, {{1.0, 0.0}}, Pose2()).valid);
  EXPECT_FALSE(matcher.match({{1.0, 0.0}}, {}, Pose2()).valid);
  CorrelativeMatcherConfig bad;
  bad.resolution_m = 0.0;
  EXPECT_TRUE(validate(bad));
  EXPECT_FALSE(validate(CorrelativeMatcherConfig{}));
}

}  // namespace
}  // namespace traverse::backend

namespace traverse::backend {
namespace {

// Reference points scattered by a wrong pose (kilometres away, or not finite) used to size the
// lookup table by their extent: std::bad_alloc on CARMEN intel. The table now covers only what
// the query can reach from the guess, so the match is the one without them; a query whose points
// reach beyond any sensible table is no match, not an allocation.
TEST(CorrelativeMatcher, GarbageExtentsNeitherAllocateNorChangeTheMatch) {
  std::mt19937 rng(7);
  const World world = test::synthetic::room();
  std::vector<Eigen::Vector2d> reference;
  for (const auto& p : test::key_points(world, Pose2(), 20.0, rng)) {
    reference.push_back(p.cast<double>());
  }
  std::vector<Eigen::Vector2d> query =
      test::to_double(test::key_points(world, Pose2(0.8, 0.5, 0.3), 20.0, rng));
  const Pose2 guess(0.9, 0.4, 0.35);
  const CorrelativeMatcher matcher(wide());
  const MatchResult clean = matcher.match(reference, query, guess);
  std::vector<Eigen::Vector2d> garbage = reference;
  garbage.emplace_back(-1.7e4, 1.8e4);
  garbage.emplace_back(1e300, -1e300);
  garbage.emplace_back(std::nan(""), 0.0);
  const MatchResult m = matcher.match(garbage, query, guess);
  ASSERT_TRUE(clean.valid && m.valid);
  EXPECT_LT((m.T_world_query.translation() - clean.T_world_query.translation()).norm(), 0.021);
  EXPECT_LT(std::abs(wrap_angle(m.T_world_query.theta() - clean.T_world_query.theta())), 0.004);

  query.insert(query.begin(), Eigen::Vector2d(1e9, 0.0));  // thinning keeps the first point
  EXPECT_FALSE(matcher.match(reference, query, guess).valid);
  EXPECT_FALSE(matcher
                   .match(reference, test::to_double(test::key_points(world, Pose2(), 20.0, rng)),
                          Pose2(std::nan(""), 0.0, 0.0))
                   .valid);
}

}  // namespace
}  // namespace traverse::backend
