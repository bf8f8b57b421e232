// The frontend's correlative searches on one occupancy grid (Olson 2009), made of the parts in
// common/correlative_search.hpp:
//   - the recovery search of the scan matcher (scan_matcher.hpp): exhaustive over a window on the
//     coarsest grid, scoring occupied evidence under the points, for a new Gauss-Newton start
//     when a match failed;
//   - the wide search for sparse scans (below).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "correlative_search.hpp"
#include "occupancy_grid.hpp"
#include "se2.hpp"
#include "step_prior.hpp"

namespace traverse::frontend {

// Best pose within +-linear_window_m (x, y) and +-angular_window_rad of T_center by exhaustive
// search on `grid` (steps of one cell, and of the angle that moves the farthest point one cell),
// scoring occupied evidence max(0, 2 (p - 0.5)) under the points (at most 200 of them, evenly
// spaced). Of the poses within 3 % of the best score, the one nearest the centre wins, so that a
// direction the scan cannot tell apart (a corridor's axis) keeps the centre's value.
Pose2 search_pose(const OccupancyGrid& grid, const std::vector<Eigen::Vector2d>& points_base,
                  const Pose2& T_center, double linear_window_m, double angular_window_rad);

// Wide search for scans far from the previous one (sparse logs, no odometry): correlative
// matching (Olson 2009) over x, y and heading by a two-level branch and bound, exact at the
// grid's resolution. The score of a pose is the summed evidence 2 (p - 0.5) under the points:
// positive on occupied cells, negative on cells seen free (a point there contradicts the pose:
// what tells a step forward from none in a corridor a 180-degree scanner looks down), zero where
// unknown. Occupied evidence is blurred by a cell (a point one cell off still scores half), so
// that a pose a fraction of a cell off is not scored as a miss. Angle steps move the point at the
// 90th percentile of range by one cell. A motion prior (the score loses 0.05 per point at one
// half-window from the nearest prior pose, quadratically) and, if given, a step prior
// (step_prior.hpp) decide where the scan cannot: they are the search's prior hook. With a
// temperature, the search also keeps every pose near the best and reports their spread: how far the
// scores leave the pose open.
struct WideSearchResult {
  Pose2 T_map_base;
  double score = 0.0;     // [unitless] mean evidence per point at the best pose, -1 to 1
  int64_t evaluated = 0;  // poses scored exactly (the rest were pruned by their bound)
  // Spread of the pose over the score surface (temperature > 0): the second moment of (x [m],
  // y [m], theta [rad]) about the best pose, of the poses weighted by exp((score - best score) /
  // temperature), the score being summed evidence with the priors. Large where the scan
  // cannot tell poses apart (along a corridor) or two poses fit alike; zero when no other pose
  // comes near the best.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int64_t poses_in_spread = 0;  // poses within 8 temperatures of the best
};

// The search's score of one pose without priors: mean evidence per point, -1 to 1 (as
// WideSearchResult::score).
double pose_evidence(const OccupancyGrid& grid, const std::vector<Eigen::Vector2d>& points_base,
                     const Pose2& T_map_base);

WideSearchResult wide_search(const OccupancyGrid& grid,
                             const std::vector<Eigen::Vector2d>& points_base, const Pose2& T_center,
                             double linear_window_m, double angular_window_rad,
                             const std::vector<Pose2>& priors = {}, double temperature = 0.0,
                             const StepPrior* step_prior = nullptr);

}  // namespace traverse::frontend
