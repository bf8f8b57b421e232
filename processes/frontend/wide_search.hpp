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
// half-window from the nearest prior pose, quadratically) and, if given, a step prior (StepPrior,
// below) decide where the scan cannot. With a temperature, the search also keeps every pose near
// the best and reports their spread: how far the scores leave the pose open.
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
// Prior on the shape of a step from T_last, for a wheeled platform whose log was subsampled by
// travel (the CARMEN sets keep a scan when odometry has moved about 1 m or turned about 0.5 rad):
//   - a step both shorter than min_travel_m and turning less than min_turn_rad is unlikely: it
//     loses short_weight * s^2 per point, s = 1 - max(length / min_travel_m, |turn| /
//     min_turn_rad) (1 standing still, 0 on the border);
//   - wheels roll along an arc: a step off the arc through its own turn (sideways by more than
//     off_arc_free_m, or backwards by more than that) loses off_arc_weight per point at 0.3 m
//     beyond, quadratically.
// It is what tells a stall (the scan fits where the last one was: along a corridor) or a slide
// sideways from the real step where the scan cannot; where the scan can, its evidence outweighs
// it (a point on an occupied cell against a free one is 2).
struct StepPrior {
  Pose2 T_last;
  double min_travel_m = 0.0, min_turn_rad = 0.0;  // 0: no prior
  double short_weight = 0.0;                      // [per point]
  double off_arc_free_m = 0.0;
  double off_arc_weight = 0.0;  // [per point]
};
// The search's score of one pose without priors: mean evidence per point, -1 to 1 (as
// WideSearchResult::score).
double pose_evidence(const OccupancyGrid& grid, const std::vector<Eigen::Vector2d>& points_base,
                     const Pose2& T_map_base);
// The step prior's cost per point of the step to T_map_base (0 without a prior).
double step_prior_cost(const StepPrior& prior, const Pose2& T_map_base);

WideSearchResult wide_search(const OccupancyGrid& grid,
                             const std::vector<Eigen::Vector2d>& points_base, const Pose2& T_center,
                             double linear_window_m, double angular_window_rad,
                             const std::vector<Pose2>& priors = {}, double temperature = 0.0,
                             const StepPrior* step_prior = nullptr);

}  // namespace traverse::frontend
