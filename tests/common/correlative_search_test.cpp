// The correlative search module (common/correlative_search.hpp): its branch and bound against an
// exhaustive search, and the three searches made of it (the frontend's recovery search and wide
// search, the backend's matcher) run through one suite: each finds a known pose in a synthetic
// room from seeded starts off it, and each that reports a covariance reports it wide along a
// corridor's axis and narrow across.
#include "correlative_search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <random>
#include <tuple>

#include "correlative_matcher.hpp"
#include "hector/grid_search.hpp"
#include "test_scans.hpp"

namespace traverse {
namespace {

namespace fe = frontend;

// The block bound is the largest cell of each k x k block, cut at the table's edges: the same
// as taking it cell by cell, for blocks wider than the table and tables not a multiple of k.
TEST(CorrelativeSearch, BlockBoundIsTheLargestCellOfEachBlock) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  for (const auto& [w, h] :
       {std::pair{37, 23}, std::pair{8, 8}, std::pair{1, 5}, std::pair{3, 1}}) {
    correlative::ScoreTable table(w, h);
    for (int j = 0; j < h; ++j) {
      for (int i = 0; i < w; ++i) table.at(i, j) = value(rng);
    }
    for (const int k : {1, 2, 3, 8, 40}) {
      const correlative::BlockBound bound(table, k);
      for (int j = 0; j < h; ++j) {
        for (int i = 0; i < w; ++i) {
          float m = 0.0f;
          for (int jj = j; jj < std::min(j + k, h); ++jj) {
            for (int ii = i; ii < std::min(i + k, w); ++ii) m = std::max(m, table.at(ii, jj));
          }
          ASSERT_EQ(bound.at(i, j), m) << w << "x" << h << " k " << k << " at " << i << ", " << j;
        }
      }
    }
  }
}

// Branch and bound over blocks of 4 x 4 (with a prior that is a valid bound) finds the pose an
// exhaustive search finds, with the same score, scoring far fewer poses; a margin makes it score
// every pose within the margin of the best.
TEST(CorrelativeSearch, BranchAndBoundFindsTheExhaustiveSearchsBest) {
  // A table of scattered peaks (as a scan's end points blurred), a little noise, and points
  // that fall on most of them at one pose.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0), noise(-0.05, 0.05);
  std::vector<Eigen::Vector2d> points(60);
  for (auto& p : points) p = {coordinate(rng), coordinate(rng)};
  const double res = 0.05;
  const Pose2 T_true(0.3, -0.1, 0.35);
  correlative::ScoreTable table(120, 120);
  for (int j = 0; j < table.height(); ++j) {
    for (int i = 0; i < table.width(); ++i) {
      const Eigen::Vector2d c((i - 60) * res, (j - 60) * res);
      double v = noise(rng);
      for (const auto& p : points) v += std::exp(-(T_true * p - c).squaredNorm() / (2 * 0.1 * 0.1));
      table.at(i, j) = static_cast<float>(v);
    }
  }
  const correlative::RotatedScans scans(
      points, Pose2(0.1, -0.2, 0.3), 10, 0.01, [&](const Eigen::Vector2d& q) {
        return std::pair<int, int>(static_cast<int>(std::floor(q.x() / res)) + 60,
                                   static_cast<int>(std::floor(q.y() / res)) + 60);
      });
  // A motion prior: the squared distance of the block's nearest translation from the centre.
  const auto nearest = [](int lo, int size) { return lo > 0 ? lo : std::max(0, -(lo + size - 1)); };
  const auto prior = [&](double sum, int a, int dx, int dy, int size) {
    const int x = nearest(dx, size), y = nearest(dy, size);
    return sum - 0.05 * (x * x + y * y) - 0.5 * std::abs(a - 10);
  };
  // Every pose scored, in the search's order of headings, rows, columns.
  correlative::ScoredPose<double> best{-1e300, 10, 0, 0};
  std::vector<double> scores;
  for (int a = 0; a < scans.headings(); ++a) {
    for (int dy = -16; dy <= 16; ++dy) {
      for (int dx = -16; dx <= 16; ++dx) {
        scores.push_back(prior(scans.sum<double>(table, a, dx, dy), a, dx, dy, 1));
        if (scores.back() > best.score) best = {scores.back(), a, dx, dy};
      }
    }
  }
  const auto pruned = correlative::branch_and_bound<double>(
      scans, table, correlative::BlockBound(table, 4), 16, {-1e300, 10, 0, 0}, 0.0, prior,
      [](const auto&, double) {});
  EXPECT_EQ(pruned.best.score, best.score);
  EXPECT_EQ(std::tie(pruned.best.a, pruned.best.dx, pruned.best.dy),
            std::tie(best.a, best.dx, best.dy));
  EXPECT_EQ(pruned.blocks, 21 * 9 * 9);
  EXPECT_LT(pruned.scored, static_cast<int64_t>(scores.size()) / 4);
  // With a margin, every pose scoring within it of the best is seen.
  const double margin = 2.0;
  const auto within = std::count_if(scores.begin(), scores.end(),
                                    [&](double s) { return s > best.score - margin; });
  int64_t seen = 0;
  correlative::branch_and_bound<double>(
      scans, table, correlative::BlockBound(table, 4), 16, {-1e300, 10, 0, 0}, margin, prior,
      [&](const auto& p, double) { seen += p.score > best.score - margin; });
  EXPECT_GT(within, 1);
  EXPECT_EQ(seen, within);
}

// The spread about the chosen pose and about the mean: two poses of equal weight 1 m apart.
TEST(CorrelativeSearch, ScoreSpreadAboutTheChosenPoseAndAboutTheMean) {
  correlative::ScoreSpread spread;
  spread.add(1.0, Eigen::Vector3d::Zero());
  spread.add(1.0, Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(spread.about_chosen()(0, 0), 0.5);
  EXPECT_DOUBLE_EQ(spread.about_mean()(0, 0), 0.25);
  EXPECT_EQ(correlative::ScoreSpread().about_chosen(), Eigen::Matrix3d::Zero());
}

// One search as the suite runs it: the pose it finds for a scan taken at `truth`, searched from
// `start`, in a map of `world` made from scans at kMapPoses; its covariance, if it gives one.
struct Found {
  Pose2 pose;
  std::optional<Eigen::Matrix3d> covariance;
};
using Search =
    std::function<Found(const fe::synthetic::World& world, const Pose2& truth, const Pose2& start)>;
const std::vector<Pose2> kMapPoses{Pose2(0.3, -0.2, 0.1), Pose2(-1.5, 1.0, 0.0)};

struct SearchCase {
  const char* name;
  Search search;
  double tolerance_m, tolerance_rad;  // of the pose found: about a cell and an angle step
  friend void PrintTo(const SearchCase& c, std::ostream* os) { *os << c.name; }
};

Found recovery_search(const fe::synthetic::World& world, const Pose2& truth, const Pose2& start) {
  const fe::MapPyramid maps = fe::testing::build_map(world, kMapPoses);
  return {
      fe::search_pose(maps.level(0), fe::testing::static_scan(world, truth, 720), start, 0.5, 0.4),
      std::nullopt};
}

Found wide_search(const fe::synthetic::World& world, const Pose2& truth, const Pose2& start) {
  const fe::MapPyramid maps = fe::testing::build_map(world, kMapPoses);
  const fe::WideSearchResult r = fe::wide_search(
      maps.level(1), fe::testing::static_scan(world, truth, 720), start, 2.0, 1.5, {start}, 3.0);
  return {r.T_map_base, r.covariance};
}

Found backend_matcher(const fe::synthetic::World& world, const Pose2& truth, const Pose2& start) {
  std::vector<Eigen::Vector2d> reference;
  for (const Pose2& T : kMapPoses) {
    for (const auto& p : fe::testing::static_scan(world, T, 1440)) reference.push_back(T * p);
  }
  backend::CorrelativeMatcherConfig config;
  config.linear_window_m = 0.5;
  config.angular_window_rad = 0.3;
  config.penalty_sigma_xy_m = 10.0;  // practically no penalty
  config.penalty_sigma_theta_rad = 10.0;
  const backend::MatchResult r = backend::CorrelativeMatcher(config).match(
      reference, fe::testing::static_scan(world, truth, 720), start);
  return {r.T_world_query, r.covariance};
}

class CorrelativeSearches : public ::testing::TestWithParam<SearchCase> {};

TEST_P(CorrelativeSearches, FindAKnownPoseFromStartsOffIt) {
  const SearchCase& c = GetParam();
  const auto room = fe::synthetic::room();
  const Pose2 truth(0.5, 0.4, 0.3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> off_m(-0.3, 0.3), off_rad(-0.2, 0.2);
  for (int k = 0; k < 4; ++k) {
    const Pose2 start(truth.x() + off_m(rng), truth.y() + off_m(rng), truth.theta() + off_rad(rng));
    const Found found = c.search(room, truth, start);
    EXPECT_LT((found.pose.translation() - truth.translation()).norm(), c.tolerance_m) << k;
    EXPECT_LT(std::abs(wrap_angle(found.pose.theta() - truth.theta())), c.tolerance_rad) << k;
  }
}

TEST_P(CorrelativeSearches, SpreadIsWideAlongACorridorAndNarrowAcross) {
  const SearchCase& c = GetParam();
  const auto corridor = fe::synthetic::corridor(60.0, 2.4);
  const Found found = c.search(corridor, Pose2(0.0, 0.3, 0.0), Pose2(0.1, 0.35, 0.02));
  EXPECT_LT(std::abs(found.pose.y() - 0.3), c.tolerance_m);  // across: found
  if (!found.covariance) return;  // the recovery search gives a pose only
  EXPECT_GT((*found.covariance)(0, 0), 10.0 * (*found.covariance)(1, 1));
  EXPECT_GT(std::sqrt((*found.covariance)(0, 0)), 0.1);  // [m] along: spread over the window
}

INSTANTIATE_TEST_SUITE_P(
    Searches, CorrelativeSearches,
    ::testing::Values(SearchCase{"frontend_recovery", recovery_search, 0.11, 0.03},
                      SearchCase{"frontend_wide", wide_search, 0.11, 0.03},
                      SearchCase{"backend_matcher", backend_matcher, 0.04, 0.01}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace traverse
