// How good the annotator's bounds are, against ground truth (scripts/eval-coverage.sh):
//   - coverage: the share of key poses whose true position error lies inside the published 95 %
//     bound (should be near 0.95; 0.90-0.99 is accepted);
//   - NEES (normalised estimation error squared, Bar-Shalom et al. 2001) of the backend's raw
//     marginal covariances, e^T Sigma_xy^-1 e, which is chi-square with two degrees of freedom when
//     the covariances are right: the covariance scale that makes them so, fitted by its mean
//     (mean NEES / 2) or by its 95 % quantile (q95 / 5.991, the quantile the bounds stand on);
//   - the scale each key pose needs to lie inside its published radius, and the one giving 95 %
//     coverage (NEES also judges the covariance's shape; the published bound is a radius);
//   - local coverage: for each key pose, the largest error of its position relative to a key pose
//     within the local radius (in its own frame) against its local bound;
//   - seed 004's claim: the mean true error of the points placed from the key poses of each level.
// Gauge: the first key pose is fixed in the backend (its covariance is zero), so the ground truth
// is aligned at it: T_world_truth = T_world_key0 * T_truth_key0^-1, and the errors of the other
// key poses are in the backend's world frame, as their covariances are.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::annotator {

struct KeyRecord {
  int64_t id = 0;
  int64_t utime = 0;                                     // [us]
  Pose2 T_world_base;                                    // final estimate
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // raw marginal (KEY_POSES)
  double bound_m = -1.0;                     // [m] published absolute bound; -1 when none
  double local_bound_m = -1.0;               // [m] published local bound; -1 when none
  int level = -1;                            // published level; -1 when none
  std::vector<Eigen::Vector2d> points_base;  // [m] points of the key pose's scan, base frame
};

struct StampedTruth {
  int64_t utime = 0;  // [us]
  Pose2 T_world_base;
};

struct LevelFigure {
  int level = 0;
  int key_poses = 0;
  int64_t points = 0;
  double mean_point_error_m = 0.0;  // [m]
  double mean_bound_m = 0.0;        // [m] mean of the bounds that gave the level
};

struct CoverageResult {
  int key_poses = 0;      // with ground truth and a published bound (key 0 excluded)
  double coverage = 0.0;  // [0..1] inside the absolute bound
  int local_key_poses = 0;
  double local_coverage = 0.0;   // [0..1] inside the local bound
  double position_rmse_m = 0.0;  // [m] of the key poses against the aligned ground truth
  double mean_bound_m = 0.0;     // [m]
  double nees_mean = 0.0, nees_median = 0.0, nees_q95 = 0.0;  // raw covariances, 2 dof
  double scale_by_mean = 0.0;                                 // nees_mean / 2
  double scale_by_q95 = 0.0;                                  // nees_q95 / 5.991
  std::vector<double> nees;                                   // per key pose (for pooling runs)
  // Per key pose, the covariance scale at which its true error would lie exactly on its bound:
  // (|e| / bound)^2 * published_scale (the bound grows with the square root of the scale). The
  // share of these at or below s is the coverage the scale s would give.
  std::vector<double> needed_scale;
  double scale_by_coverage = 0.0;  // q95(needed_scale): the scale giving 95 % coverage
  std::vector<LevelFigure> levels;
  bool levels_increasing = false;  // mean point error strictly increasing with the level
};

// The ground truth at `utime`, interpolated between its neighbours; nullopt outside it.
std::optional<Pose2> truth_at(const std::vector<StampedTruth>& truth, int64_t utime);

// Everything above for key poses sorted by id (the first one fixes the frame); `local_radius_m`
// and `published_scale` (the covariance scale of the published bounds) as the annotator's.
CoverageResult evaluate_coverage(const std::vector<KeyRecord>& keys,
                                 const std::vector<StampedTruth>& truth, double local_radius_m,
                                 double published_scale = 1.0);

// The q-quantile (0..1) of values by linear interpolation; 0 for none.
double quantile(std::vector<double> values, double q);

}  // namespace traverse::annotator
