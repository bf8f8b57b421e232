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
// it (a point on an occupied cell against a free one is 2). The Hector core's wide search weighs
// it (hector/grid_search.hpp), and so does the lag (sparse/lag.hpp) when it compares two poses.
#pragma once

#include "frontend_config.hpp"
#include "se2.hpp"

namespace traverse::frontend {

struct StepPrior {
  Pose2 T_last;
  double min_travel_m = 0.0, min_turn_rad = 0.0;  // 0: no prior
  double short_weight = 0.0;                      // [per point]
  double off_arc_free_m = 0.0;
  double off_arc_weight = 0.0;  // [per point]

  bool active() const { return min_travel_m > 0.0 && min_turn_rad > 0.0; }
};

// The step prior of config's sparse_step_* keys for a step from T_last.
StepPrior step_prior(const MatcherConfig& config, const Pose2& T_last);

// The prior's cost per point of the step to T_map_base (0 without a prior).
double step_prior_cost(const StepPrior& prior, const Pose2& T_map_base);

// The cost per point of a step of `length` [m], `forward` [m] along the last heading, `side` [m]
// off the arc through its `turn` [rad] (0 on it). A search bounds a block of steps by the
// largest length and forward part and the least side of its corners.
double step_shape_cost(const StepPrior& prior, double length, double forward, double side,
                       double turn);

// Tangent of half a step's turn: a chord of an arc turning by `turn` points half as far round
// (sideways = forward * tan).
double tan_half_turn(double turn);

}  // namespace traverse::frontend
