// Points of a scan that lie where the map has seen through: free space all around, observed
// free over several updates. What stands there now moved in since (people walking through the
// scans, a door that closed, a chair pushed aside) or is no surface at all (a mixed pixel between
// an edge and the wall behind it). Matched, such points pull the pose towards where the map holds
// something similar (the legs the map took in a moment ago, along a corridor's axis); taken into
// the map, they leave traces that later scans are pulled by. They are left out of both.
//
// A point is seen through when no cell of the 3 x 3 cells around it on the given grid (the
// matcher uses level 1, 0.1 m: a prediction a few cm off keeps a wall's points) has an
// occupancy probability at or above max_probability (0.25: three free traversals of a cell
// that never held a hit). Unobserved cells (0.5) never make a point seen through: a new area's
// surfaces come in.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "occupancy_grid.hpp"
#include "se2.hpp"

namespace traverse::frontend {

// One flag per point (base frame), placed at T_map_base: true where the grid has seen through.
std::vector<bool> seen_through(const OccupancyGrid& grid,
                               const std::vector<Eigen::Vector2d>& points_base,
                               const Pose2& T_map_base, double max_probability);

}  // namespace traverse::frontend
