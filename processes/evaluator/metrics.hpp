// Error figures of a trajectory matched pose by pose with its reference.
//
// - Absolute errors (seed 000, Table 2): RMSE, standard deviation and maximum of the position
//   error |t_est - t_ref| and of the heading error |wrap(theta_est - theta_ref)|. The SD is the
//   population SD of those magnitudes (as the Rawseeds toolkit the paper used), so a constant
//   offset gives RMSE = max = offset and SD = 0.
// - Relative pose error over a travel distance d (Sturm et al. 2012, Geiger et al. 2012 in its
//   distance form): for every matched pose i, the first later pose j at least d further along the
//   reference; E = (T_ref_i^-1 T_ref_j)^-1 (T_est_i^-1 T_est_j); RMS of |trans(E)|. Independent
//   of the alignment, it shows drift per distance where absolute errors show accumulated drift.
// - Largest jump: max over consecutive matched estimates of |est step - true step|, each step the
//   motion from the previous pose expressed in that pose's frame (a one-step relative error), so
//   a loop closure that moves the estimate by 0.3 m shows as 0.3 m whatever the heading error.
// - Step consistency: each step's translation error (as for the largest jump) against the step
//   covariance made of both poses' reported covariances, taken as independent (right for a
//   scan-to-map frontend's per-scan covariance), with the start pose's heading variance swinging
//   the step: NEES = e^T S^-1 e, chi-square with 2 degrees of freedom when the covariances are
//   right (median 1.39, 1 % above 9.21). Median and fraction above 9.21.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "se2.hpp"

namespace traverse::evaluator {

struct ErrorStats {
  double rmse = 0.0;
  double sd = 0.0;
  double max = 0.0;
};

// Statistics of non-negative error magnitudes; all zero for an empty input.
ErrorStats error_stats(const std::vector<double>& magnitudes);

struct RelativeError {
  std::optional<double> rms_m;  // [m] nullopt when the reference never travels distance_m
  std::size_t pairs = 0;
};

// `est`, `ref` matched pairs in time order; `travel_m` the reference path length at each pair.
RelativeError relative_pose_error(const std::vector<Pose2>& est, const std::vector<Pose2>& ref,
                                  const std::vector<double>& travel_m, double distance_m);

struct Jump {
  double step_error_m = 0.0;  // [m] |est step - true step|
  std::size_t index = 0;      // pair index at the end of that step (0 when fewer than 2 pairs)
};

Jump max_jump(const std::vector<Pose2>& est, const std::vector<Pose2>& ref);

struct StepConsistency {
  std::size_t steps = 0;              // steps whose two poses carry a positive definite covariance
  std::optional<double> nees_median;  // [unitless] nullopt without such steps
  std::optional<double> outside_99_fraction;  // [unitless, 0 to 1] NEES above 9.21
};

// `cov[i]`: covariance of est[i] in the frame est is expressed in (zero: unknown, skipped).
StepConsistency step_consistency(const std::vector<Pose2>& est,
                                 const std::vector<Eigen::Matrix3d>& cov,
                                 const std::vector<Pose2>& ref);

}  // namespace traverse::evaluator
