// Trajectory evaluation as in seed 000 (Section 4, Table 2, Figure 3): an estimated trajectory is
// matched by time with a reference (interpolated at each estimate time), brought into the
// reference frame (alignment.hpp), and summarised by absolute position and heading errors,
// relative pose errors over 1 m and 10 m of travel, and the largest jump (metrics.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "alignment.hpp"
#include "final_trajectory.hpp"
#include "loop_closures.hpp"
#include "metrics.hpp"
#include "relations.hpp"
#include "trajectory.hpp"

namespace traverse::evaluator {

struct EvaluatorConfig {
  std::string align = "first_pose";  // none | first_pose | se2 (see alignment.hpp)
  MatchConfig match;
  // [standard deviations] a loop closure whose error against the reference has a Mahalanobis
  // distance above this is false (loop_closures.hpp).
  double false_closure_sigmas = 5.0;
  // key_poses_t channel whose loop closures are checked (the backend's; absent without one).
  std::string key_poses_channel = "KEY_POSES";
  // [0..1] No figures (exit non-zero) when the estimate covers less than this share of the
  // reference: of its poses (those inside the span of the matched estimate), or of the relations
  // (--relations). A stage that stopped early or published a single pose is a failure, not a
  // perfect run.
  double min_reference_share = 0.8;
  // [us] --relations: a pose this close to a relation's scan stamp is that scan's (relations.hpp).
  int64_t relation_time_tolerance_us = 0;

  template <class V>
  void visit(V& v) {
    v("align", align);
    v("max_reference_gap_us", match.max_reference_gap_us);
    v("edge_tolerance_us", match.edge_tolerance_us);
    v("false_closure_sigmas", false_closure_sigmas);
    v("key_poses_channel", key_poses_channel);
    v("min_reference_share", min_reference_share);
    v("relation_time_tolerance_us", relation_time_tolerance_us);
  }
};

// The one place a config is checked: an error message naming the key, or nullopt.
std::optional<std::string> validate(const EvaluatorConfig& config);

// Adds (dx [m], dy [m], dtheta [rad]) to every pose's (x, y, theta): a known error to check the
// evaluator with (a shifted ground truth must show exactly this offset with align none).
void shift(Trajectory& trajectory, double dx_m, double dy_m, double dtheta_rad);

struct ErrorSample {
  int64_t utime = 0;               // [us]
  Pose2 T_ref_est;                 // the estimate, aligned into the reference frame
  Pose2 T_ref_true;                // the reference interpolated at utime
  double position_error_m = 0.0;   // [m] |t_est - t_true|
  double heading_error_rad = 0.0;  // [rad] wrap(theta_est - theta_true), signed
  double travel_m = 0.0;           // [m] reference path length since its first pose
};

struct Evaluation {
  std::vector<ErrorSample> samples;  // one per matched estimate, in time order
  std::size_t estimate_poses = 0;    // after dropping repeated times
  std::size_t reference_poses = 0;
  std::size_t matched = 0;
  std::size_t unmatched = 0;  // outside the reference span or inside a reference gap
  // Reference poses from the first to the last matched estimate's time, and their share of all:
  // how much of the reference the estimate covers.
  std::size_t reference_covered = 0;
  double reference_share = 0.0;
  bool refused = false;  // reference_share below the config's min_reference_share
  Alignment alignment;
  ErrorStats position_m;   // [m]
  ErrorStats heading_rad;  // [rad] of |heading error|
  RelativeError rpe_1m;
  RelativeError rpe_10m;
  Jump max_jump;                     // index into samples
  StepConsistency step_consistency;  // of the estimate's reported covariances (metrics.hpp)
  double duration_s = 0.0;           // [s] from the first to the last matched estimate
  double length_m = 0.0;             // [m] reference path length over that time
};

// Evaluates `estimate` against `reference` (any order; repeated times keep their first pose).
// `config` must have passed validate().
Evaluation evaluate(Trajectory estimate, Trajectory reference, const EvaluatorConfig& config);

}  // namespace traverse::evaluator
