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
// half-window from the nearest prior pose, quadratically) decides where the scan cannot. With a
// temperature, the search also keeps every pose near the best and reports their spread: how far
// the scores leave the pose open.
struct WideSearchResult {
  Pose2 T_map_base;
  double score = 0.0;     // [unitless] mean evidence per point at the best pose, -1 to 1
  int64_t evaluated = 0;  // poses scored exactly (the rest were pruned by their bound)
  // Spread of the pose over the score surface (temperature > 0): the second moment of (x [m],
  // y [m], theta [rad]) about the best pose, of the poses weighted by exp((score - best score) /
  // temperature), the score being summed evidence with the motion prior. Large where the scan
  // cannot tell poses apart (along a corridor) or two poses fit alike; zero when no other pose
  // comes near the best.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int64_t poses_in_spread = 0;  // poses within 8 temperatures of the best
};
WideSearchResult wide_search(const OccupancyGrid& grid,
                             const std::vector<Eigen::Vector2d>& points_base, const Pose2& T_center,
                             double linear_window_m, double angular_window_rad,
                             const std::vector<Pose2>& priors = {}, double temperature = 0.0);

}  // namespace traverse::frontend
