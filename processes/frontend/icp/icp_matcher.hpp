// Point-to-line ICP of one scan against the point map (Censi, "An ICP variant using a
// point-to-line metric", ICRA 2008, solved by Gauss-Newton instead of in closed form): each query
// point q = T p is paired with the nearest map point m and its normal n, and the pose T = (x, y,
// theta) minimises sum_i rho(n_i . (T p_i - m_i)) plus a weak prior towards the prediction, with
// a Cauchy kernel rho of scale kernel_m (iteratively reweighted). Correspondences are sought
// within max_correspondence_m until the steps converge, then within final_correspondence_m.
//
// Covariance: the inverse of the information of the last linearisation, sigma^-2 J^T W J plus the
// prior's, with sigma^2 the weighted mean squared residual (at least min_residual_sigma_m^2):
// for independent range noise this is the Cramér-Rao bound of the point-to-line problem (units
// m^2, m rad, rad^2 in the map frame; tests/frontend/icp_test.cpp checks both the units and the
// consistency). Errors of the map's own points are not in it, so on real data it is optimistic.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "icp_config.hpp"
#include "point_map.hpp"
#include "se2.hpp"

namespace traverse::frontend {

struct IcpResult {
  Pose2 T_map_base;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // (x [m], y [m], theta [rad]), map
  int iterations = 0;
  int correspondences = 0;       // query points paired at the end
  double inlier_fraction = 0.0;  // ... of all query points
  double residual_rms_m = 0.0;   // [m] RMS point-to-line distance of the pairs
  bool converged = false;
};

// Matches points (base frame) against `map` from T_start; the prior pulls towards T_prior with
// the given information (map frame, 1/m^2 and 1/rad^2).
IcpResult match_point_to_line(const PointMap& map, const std::vector<Eigen::Vector2d>& points_base,
                              const Pose2& T_start, const Pose2& T_prior,
                              const Eigen::Matrix3d& prior_information, const IcpConfig& config);

}  // namespace traverse::frontend
