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
