// Scan-to-map matching by Gauss-Newton on a multi-resolution occupancy grid pyramid.
//
// Follows Kohlbrecher et al. 2011 (Hector SLAM), section IV.B: find the pose xi = (x, y, psi)
// that minimises sum_i (1 - M(S_i(xi)))^2, where S_i are the scan end points moved by xi (eq. 7)
// and M the bilinearly interpolated map value. Linearising M(S_i(xi + dxi)) gives the step
// dxi = H^-1 sum_i [grad M dS_i/dxi]^T (1 - M(S_i(xi))) with H = sum_i [grad M dS_i/dxi]^T
// [grad M dS_i/dxi] (eq. 10-13). Section IV.D: start on the coarsest grid, each finer grid starts
// from the coarser result. Added to the paper: a weak prior towards the motion prediction, so
// directions the geometry leaves free keep the predicted value, and a step that raises the cost
// is halved instead of taken.
//
// Recovery (not in the paper): when the residual after Gauss-Newton says the match failed, an
// exhaustive search over a window of poses on the coarsest grid (scoring occupied evidence under
// the points, as correlative matching does, Olson 2009: search_pose() in grid_search.hpp) gives a
// new start for Gauss-Newton. Sparse scans start from the best pose of the wide search
// (grid_search.hpp) instead of the prediction.
//
// Covariance: residuals 1 - M are unitless; with the map-value noise sigma^2 estimated from the
// final residuals (sum r^2 / (n - 3), floored), the information of the pose is H / sigma^2 + P,
// where H is in 1/m^2 (translation) and 1/rad^2 (rotation) because the gradient is taken per
// metre, and P is the prior's information. Several points falling into one cell do not observe
// independent map noise, so H is divided by (points / distinct cells). The covariance is the
// inverse of that information, in m^2, m rad, rad^2.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "frontend_config.hpp"
#include "map_pyramid.hpp"
#include "se2.hpp"

namespace traverse::frontend {

struct MatchResult {
  Pose2 T_map_base;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // of (x [m], y [m], theta [rad])
  int iterations = 0;                                    // Gauss-Newton steps over all levels
  int points = 0;                                        // points matched
  double residual_rms = 0.0;  // RMS of 1 - M at the result, finest level [unitless]
  bool searched = false;      // the recovery search ran (and its result was kept)
  // What the scan's surfaces measure across themselves (the gradient along each point's surface
  // normal, surface_normals.hpp; the whole gradient when MatcherConfig::degeneracy_min_ratio and
  // normal_projection are off), scaled as the covariance is and without the matcher's weak prior
  // [1/m^2, 1/(m rad), 1/rad^2] (degeneracy.hpp).
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
};

// Estimated map-value cost and derivatives of one pose, used by the matcher and by tests.
struct NormalEquations {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // sum J^T J [1/m^2, 1/(m rad), 1/rad^2]
  Eigen::Vector3d g = Eigen::Vector3d::Zero();  // sum J^T r
  double cost = 0.0;                            // sum r^2
  int n = 0;
};
// With normals (base frame, one per point; zero: none), each point's map gradient is taken only
// along its normal (surface_normals.hpp). `at_hits`: OccupancyGrid::value's.
NormalEquations normal_equations(const OccupancyGrid& grid,
                                 const std::vector<Eigen::Vector2d>& points_base,
                                 const Pose2& T_map_base,
                                 const std::vector<Eigen::Vector2d>* normals_base = nullptr,
                                 bool at_hits = true);

// Wide search around priors[0] (not empty) on pyramid level min(1, levels - 1) with a motion
// prior towards the nearest of `priors`, then Gauss-Newton over all levels from the best pose,
// with the Gauss-Newton prior centred on it. With T_last (the pose the step starts from), the
// search also weighs the step's shape (StepPrior, config's sparse_step_* keys).
MatchResult match_scan_wide(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                            const std::vector<Pose2>& priors, const MatcherConfig& config,
                            const Pose2* T_last = nullptr);

// A match with a poor fit (residual above config.search_trigger_residual) that ends farther from
// the prediction than config.search_max_unverified_m or _rad: nothing confirms such a jump.
bool unverified(const MatchResult& m, const Pose2& T_map_base_predicted,
                const MatcherConfig& config);

// Matches points (base frame) against the pyramid from T_map_base_predicted. `first_level` and
// `last_level` select the pyramid levels used, coarse to fine (defaults: all). When the result's
// residual exceeds config.search_trigger_residual, searches around the prediction and around
// each of `other_centres` (e.g. the last pose: no motion), refines each, and keeps the best of
// the candidates that are not unverified().
MatchResult match_scan(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                       const Pose2& T_map_base_predicted, const MatcherConfig& config,
                       int first_level = -1, int last_level = 0,
                       const std::vector<Pose2>& other_centres = {});

}  // namespace traverse::frontend
