// Correlative wide search (Olson 2009) for sparse scans, on one occupancy grid.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "occupancy_grid.hpp"
#include "se2.hpp"

namespace traverse::frontend {

// Wide search for scans far from the previous one (sparse logs, no odometry): correlative
// matching (Olson 2009) over x, y and heading by a two-level branch and bound, exact at the
// grid's resolution. The score of a pose is the summed evidence 2 (p - 0.5) under the points:
// positive on occupied cells, negative on cells seen free (a point there contradicts the pose:
// what tells a step forward from none in a corridor a 180-degree scanner looks down), zero where
// unknown. Occupied evidence is blurred by a cell (a point one cell off still scores half), so
// that a pose a fraction of a cell off is not scored as a miss. Angle steps move the point at the
// 90th percentile of range by one cell. A motion prior (the score loses 0.05 per point at one
// half-window from the nearest prior pose, quadratically) decides where the scan cannot.
struct WideSearchResult {
  Pose2 T_map_base;
  double score = 0.0;     // [unitless] mean evidence per point at the best pose, -1 to 1
  int64_t evaluated = 0;  // poses scored exactly (the rest were pruned by their bound)
};
WideSearchResult wide_search(const OccupancyGrid& grid,
                             const std::vector<Eigen::Vector2d>& points_base, const Pose2& T_center,
                             double linear_window_m, double angular_window_rad,
                             const std::vector<Pose2>& priors = {});

}  // namespace traverse::frontend
