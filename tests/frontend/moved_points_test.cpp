#include "hector/moved_points.hpp"

#include <gtest/gtest.h>

#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

using testing::build_map;
using testing::static_scan;

// A room the map has seen from a few places: a person standing in its open middle now is seen
// through (free all around on level 1), the walls are not, and neither is anything beyond what
// the map has observed.
TEST(MovedPoints, PointsInObservedFreeSpaceAreSeenThroughAndWallsAreNot) {
  const auto room = synthetic::room();
  const MapPyramid maps = build_map(room, {Pose2(), Pose2(-1.0, 0.5, 0.3), Pose2(1.0, -0.5, -0.2)});
  const OccupancyGrid& grid = maps.level(1);
  const Pose2 T_map_base(0.2, 0.1, 0.4);
  std::vector<Eigen::Vector2d> points = static_scan(room, T_map_base, 720, 0.003);
  const std::size_t walls = points.size();
  // Legs half a metre from the scanner, and a point far outside the mapped room (unobserved).
  const Pose2 T_base_map = T_map_base.inverse();
  for (const Eigen::Vector2d& q : {Eigen::Vector2d(0.9, 0.4), Eigen::Vector2d(0.95, 0.45),
                                   Eigen::Vector2d(0.9, 0.5), Eigen::Vector2d(300.0, 200.0)}) {
    points.push_back(T_base_map * q);
  }
  const std::vector<bool> moved = seen_through(grid, points, T_map_base, 0.25);
  ASSERT_EQ(moved.size(), points.size());
  int walls_flagged = 0;
  for (std::size_t i = 0; i < walls; ++i) walls_flagged += moved[i];
  EXPECT_EQ(walls_flagged, 0);
  EXPECT_TRUE(moved[walls]);
  EXPECT_TRUE(moved[walls + 1]);
  EXPECT_TRUE(moved[walls + 2]);
  EXPECT_FALSE(moved[walls + 3]);  // unobserved cells (0.5) never make a point seen through
  // Probability 0 as the bound: nothing is below it, nothing is flagged.
  const std::vector<bool> none = seen_through(grid, points, T_map_base, 0.0);
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
}

}  // namespace
}  // namespace traverse::frontend
