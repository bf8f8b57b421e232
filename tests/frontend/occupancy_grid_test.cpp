#include "hector/occupancy_grid.hpp"

#include <gtest/gtest.h>

#include <random>

#include "synthetic_scans.hpp"

namespace traverse::frontend {
namespace {

// A grid that has seen the synthetic room (moved by T_map_room) from a few places.
OccupancyGrid room_grid(double resolution, bool subcell = false, const Pose2& T_map_room = {}) {
  OccupancyGrid grid(resolution, 0.9, 0.4, subcell);
  synthetic::World world;
  for (const auto& s : synthetic::room()) world.push_back({T_map_room * s.a, T_map_room * s.b});
  for (const Eigen::Vector2d& origin : {Eigen::Vector2d(0, 0), Eigen::Vector2d(-2, 1)}) {
    std::vector<Eigen::Vector2d> hits;
    for (int i = 0; i < 2000; ++i) {
      const double a = 2.0 * M_PI * i / 2000.0;
      const Eigen::Vector2d d(std::cos(a), std::sin(a));
      if (auto r = synthetic::cast_ray(world, origin, d, 30.0)) hits.push_back(origin + *r * d);
    }
    grid.update(origin, hits);
  }
  return grid;
}

// Every cell's probability within +-`half` cells of the origin.
std::vector<double> cells(const OccupancyGrid& grid, int half) {
  std::vector<double> v;
  for (int j = -half; j <= half; ++j)
    for (int i = -half; i <= half; ++i) v.push_back(grid.cell_probability(i, j));
  return v;
}

TEST(OccupancyGrid, JournalRollbackUndoesUpdatesExactlyAndEndKeepsThem) {
  OccupancyGrid grid = room_grid(0.05);
  // Hits at the same cells over and over saturate their log-odds (clamped): no opposite update
  // could undo the last ones. Far hits create tiles that did not exist.
  std::vector<Eigen::Vector2d> hits{{1.0, 0.3}, {-0.7, 1.2}, {12.0, -9.0}};
  const std::vector<double> before = cells(grid, 300);
  const std::size_t tiles_before = grid.tile_count();
  const std::size_t tile_bytes = grid.memory_bytes() / tiles_before;
  grid.begin_journal();
  for (int k = 0; k < 200; ++k) grid.update({0.1, 0.2}, hits);
  ASSERT_NE(cells(grid, 300), before);
  ASSERT_GT(grid.tile_count(), tiles_before);
  // The saved tiles count in the memory reported while the journal is open.
  EXPECT_GT(grid.memory_bytes(), grid.tile_count() * tile_bytes);
  grid.rollback();
  EXPECT_EQ(grid.memory_bytes(), tiles_before * tile_bytes);
  EXPECT_FALSE(grid.journal_open());
  EXPECT_EQ(cells(grid, 300), before);
  EXPECT_EQ(grid.tile_count(), tiles_before);
  // Reads between the update and the rollback (a matcher's) do not hide a tile from the journal.
  grid.begin_journal();
  EXPECT_NEAR(grid.cell_probability(20, 6), 0.5, 0.5);
  grid.update({0.1, 0.2}, hits);
  const std::vector<double> after_one = cells(grid, 300);
  grid.rollback();
  EXPECT_EQ(cells(grid, 300), before);
  // Kept: the update stays, and a later rollback has nothing to undo.
  grid.begin_journal();
  grid.update({0.1, 0.2}, hits);
  grid.end_journal();
  EXPECT_EQ(cells(grid, 300), after_one);
  grid.rollback();
  EXPECT_EQ(cells(grid, 300), after_one);
}

TEST(OccupancyGrid, UnobservedIsHalfAndHitsAreOccupiedRaysFree) {
  OccupancyGrid grid(0.05, 0.9, 0.4);
  EXPECT_DOUBLE_EQ(grid.value({1.0, 2.0}), 0.5);
  grid.update({0.0, 0.0}, {{1.0, 0.0}});
  EXPECT_NEAR(grid.cell_probability(20, 0), 0.9, 0.01);
  EXPECT_NEAR(grid.cell_probability(10, 0), 0.4, 0.01);
  EXPECT_DOUBLE_EQ(grid.cell_probability(21, 0), 0.5);  // behind the wall: not seen
}

TEST(OccupancyGrid, HitWinsOverTraversalWithinOneScan) {
  OccupancyGrid grid(0.05, 0.9, 0.4);
  // The second beam passes through the first beam's end point cell on its way further out.
  grid.update({0.0, 0.0}, {{1.0, 0.0}, {2.0, 0.0}});
  EXPECT_GT(grid.cell_probability(20, 0), 0.85);
  EXPECT_GT(grid.cell_probability(40, 0), 0.85);
}

TEST(OccupancyGrid, InterpolatesCellValuesAtSamplePoints) {
  const OccupancyGrid grid = room_grid(0.1);
  for (int ix = -40; ix <= 40; ix += 7) {
    for (int iy = -40; iy <= 40; iy += 9) {
      EXPECT_NEAR(grid.value({ix * 0.1, iy * 0.1}), grid.cell_probability(ix, iy), 1e-9);
    }
  }
}

class GridGradient : public ::testing::TestWithParam<bool> {};

// The gradient is the map's at the point it is read at: p itself, or with sub-cell hits (the
// parameter) p - o(p) with the offset held (OccupancyGrid::value says why o's own variation is
// left out). Checked against the numerical derivative of the value read there.
TEST_P(GridGradient, MatchesNumericalDerivative) {
  const double res = 0.05;
  // Walls off the cell centres and the axes, so that neighbouring cells' offsets differ.
  const OccupancyGrid grid = room_grid(res, GetParam(), Pose2(0.013, -0.007, 0.05));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-5.5, 5.5), frac(0.1, 0.9);
  int informative = 0, mismatched = 0;
  for (int k = 0; k < 2000; ++k) {
    // Stay inside one cell so the interpolant is smooth around the point.
    const Eigen::Vector2d p(std::floor(coord(rng) / res + 0.5) * res + frac(rng) * res,
                            std::floor(coord(rng) / res + 0.5) * res + frac(rng) * res);
    Eigen::Vector2d grad;
    const double m = grid.value(p, &grad);
    const Eigen::Vector2d read_at = p - grid.hit_offset(p);
    EXPECT_DOUBLE_EQ(m, grid.value(read_at, nullptr, false));
    const auto plain = [&](double dx, double dy) {
      return grid.value(read_at + Eigen::Vector2d(dx, dy), nullptr, false);
    };
    const double h = 1e-7;
    const double gx = (plain(h, 0) - plain(-h, 0)) / (2 * h);
    const double gy = (plain(0, h) - plain(0, -h)) / (2 * h);
    if (std::abs(grad.x() - gx) > 1e-4 * (1.0 + std::abs(gx)) ||
        std::abs(grad.y() - gy) > 1e-4 * (1.0 + std::abs(gy))) {
      ++mismatched;
    }
    if (grad.norm() > 1.0) ++informative;
  }
  EXPECT_EQ(mismatched, 0);
  EXPECT_GT(informative, 50);  // the check saw walls, not only flat free space
}
INSTANTIATE_TEST_SUITE_P(Subcell, GridGradient, ::testing::Bool());

TEST(OccupancyGrid, GrowsBeyondAnyInitialExtentInAllDirections) {
  OccupancyGrid grid(0.05, 0.9, 0.4);
  grid.update({0, 0}, {{1, 0}});
  const std::size_t small = grid.memory_bytes();
  // A 300 m route and more, in negative and positive directions: no edge to hit.
  const std::vector<Eigen::Vector2d> far = {{310.0, 5.0}, {-250.0, -420.0}, {3.0, 1000.0}};
  for (const auto& p : far) grid.update(p - Eigen::Vector2d(0.5, 0), {p});
  for (const auto& p : far) EXPECT_GT(grid.value(p), 0.85) << p.transpose();
  EXPECT_GT(grid.memory_bytes(), small);
  EXPECT_LE(grid.min_corner().x(), -250.0);
  EXPECT_LE(grid.min_corner().y(), -420.0);
  EXPECT_GE(grid.max_corner().x(), 310.0);
  EXPECT_GE(grid.max_corner().y(), 1000.0);
  // Memory follows the area seen, not the bounding box (which would be 560 m x 1420 m).
  EXPECT_LT(grid.memory_bytes(), 20 * sizeof(int16_t) * OccupancyGrid::kTileCells);
}

TEST(OccupancyGrid, EvictsFarthestTilesToStayUnderBudget) {
  OccupancyGrid grid(0.05, 0.9, 0.4);
  for (int i = 0; i < 50; ++i) grid.update({i * 10.0, 0}, {{i * 10.0 + 1.0, 0}});
  const std::size_t budget = grid.memory_bytes() / 2;
  EXPECT_GT(grid.evict_farthest({0, 0}, budget), 0u);
  EXPECT_LE(grid.memory_bytes(), budget);
  EXPECT_GT(grid.value({1.0, 0}), 0.85);          // near the pose: kept
  EXPECT_DOUBLE_EQ(grid.value({491.0, 0}), 0.5);  // far away: forgotten
}

// Sub-cell hits: a wall 13 mm above a row of cell centres. The plain grid's ridge lies on the
// centres; with sub-cell hits it lies on the wall, and the offset read back is the wall's.
TEST(OccupancyGrid, SubcellHitsPutTheRidgeWhereTheWallWasSeen) {
  const double wall_y = 1.013;
  std::vector<Eigen::Vector2d> hits;
  for (double x = -1.0; x <= 1.0; x += 0.01) hits.emplace_back(x, wall_y);
  OccupancyGrid plain(0.05, 0.9, 0.4), subcell(0.05, 0.9, 0.4, true);
  for (int k = 0; k < 5; ++k) {
    plain.update(Eigen::Vector2d::Zero(), hits);
    subcell.update(Eigen::Vector2d::Zero(), hits);
  }
  // Where along y (through x = 0.3) the map value peaks, searched in 0.1 mm steps.
  auto ridge = [](const OccupancyGrid& g) {
    double best_y = 0.0, best = -1.0;
    for (double y = 0.95; y <= 1.05; y += 1e-4) {
      const double v = g.value(Eigen::Vector2d(0.3, y));
      if (v > best) best = v, best_y = y;
    }
    return best_y;
  };
  EXPECT_NEAR(ridge(plain), 1.0, 1e-3);
  EXPECT_NEAR(ridge(subcell), wall_y, 1e-3);
  EXPECT_NEAR(subcell.hit_offset(Eigen::Vector2d(0.3, 1.0)).y(), wall_y - 1.0, 1e-3);
  EXPECT_EQ(plain.hit_offset(Eigen::Vector2d(0.3, 1.0)), Eigen::Vector2d::Zero());
  // Free space says nothing about walls: no offset half way to the origin.
  EXPECT_EQ(subcell.hit_offset(Eigen::Vector2d(0.3, 0.5)), Eigen::Vector2d::Zero());
  EXPECT_GT(subcell.memory_bytes(), plain.memory_bytes());
}

}  // namespace
}  // namespace traverse::frontend
