#include "step_prior.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::frontend {
namespace {

// A step off its arc (sideways or backwards) by StepPrior::off_arc_free_m plus this loses
// StepPrior::off_arc_weight per point, quadratically.
constexpr double kOffArcScaleM = 0.3;

}  // namespace

StepPrior step_prior(const MatcherConfig& config, const Pose2& T_last) {
  return {.T_last = T_last,
          .min_travel_m = config.sparse_step_min_travel_m,
          .min_turn_rad = config.sparse_step_min_turn_rad,
          .short_weight = config.sparse_step_short_weight,
          .off_arc_free_m = config.sparse_step_off_arc_free_m,
          .off_arc_weight = config.sparse_step_off_arc_weight};
}

double tan_half_turn(double turn) {
  return std::tan(std::clamp(0.5 * turn, -M_PI / 4.0, M_PI / 4.0));
}

double step_shape_cost(const StepPrior& sp, double length, double forward, double side,
                       double turn) {
  double cost = 0.0;
  const double inside = 1.0 - std::max(length / sp.min_travel_m, std::abs(turn) / sp.min_turn_rad);
  if (inside > 0.0) cost += sp.short_weight * inside * inside;
  const double e_side = std::max(0.0, side - sp.off_arc_free_m) / kOffArcScaleM;
  const double e_back = std::max(0.0, -forward - sp.off_arc_free_m) / kOffArcScaleM;
  return cost + sp.off_arc_weight * (e_side * e_side + e_back * e_back);
}

double step_prior_cost(const StepPrior& sp, const Pose2& T_map_base) {
  if (!sp.active()) return 0.0;
  const Pose2 step = between(sp.T_last, T_map_base);
  const Eigen::Vector2d v = step.translation();
  return step_shape_cost(sp, v.norm(), v.x(), std::abs(v.y() - v.x() * tan_half_turn(step.theta())),
                         step.theta());
}

}  // namespace traverse::frontend
