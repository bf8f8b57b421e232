// Configuration of the ICP frontend (icp_frontend.hpp), FrontendConfig::icp: lengths m, angles
// rad. The motion prior, de-skew, scanner extrinsics and initial pose are the frontend's common
// keys (frontend_config.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace traverse::frontend {

struct IcpConfig {
  // The map: points of the key scans with their normals, at most one per point_spacing_m, in a
  // hash of cells of cell_m (point_map.hpp). A correspondence is searched in the point's cell
  // and its eight neighbours, so cell_m bounds how far the first iterations reach.
  double cell_m = 0.3;
  double point_spacing_m = 0.03;
  // A scan enters the map when the pose moved this far or turned this much since the last one.
  double key_distance_m = 0.1;
  double key_angle_rad = 0.05;
  // Map cells farther than this from the pose are dropped (the map follows the platform; the
  // office routes revisit within it, so old passes keep anchoring the pose).
  double map_radius_m = 60.0;
  // Normals: from the neighbours along the scan within normal_radius_m, at least 3; a point whose
  // neighbours do not lie on a line (smallest over largest spread above max_line_spread) has none
  // and is not used.
  double normal_radius_m = 0.12;
  double max_line_spread = 0.2;
  // Query points: the scan's valid points at least query_spacing_m apart.
  double query_spacing_m = 0.05;
  // Gauss-Newton on the point-to-line distances: correspondences within max_correspondence_m
  // (then within final_correspondence_m once the step is below convergence), Cauchy kernel of
  // scale kernel_m, at most max_iterations, done when the step is under convergence_m and
  // convergence_rad.
  double max_correspondence_m = 0.3;
  double final_correspondence_m = 0.1;
  double kernel_m = 0.03;
  int max_iterations = 30;
  double convergence_m = 1e-4;
  double convergence_rad = 1e-5;
  // Weak prior towards the motion prediction (as the Hector matcher's): holds the direction a
  // corridor does not constrain. Its information is added to the Hessian.
  double prior_sigma_xy_m = 0.5;
  double prior_sigma_theta_rad = 0.2;
  // The covariance is sigma^2 (J^T W J)^-1 (plus the prior), sigma^2 the weighted residual
  // variance, at least min_residual_sigma_m^2.
  double min_residual_sigma_m = 0.005;
  // A match with fewer than this share of query points within final_correspondence_m of the map
  // is not trusted: the pose is the prediction (flagged) and the scan stays out of the map.
  double min_inlier_fraction = 0.3;
  int min_valid_points = 20;

  template <class V>
  void visit(V& v) {
    v("cell_m", cell_m);
    v("point_spacing_m", point_spacing_m);
    v("key_distance_m", key_distance_m);
    v("key_angle_rad", key_angle_rad);
    v("map_radius_m", map_radius_m);
    v("normal_radius_m", normal_radius_m);
    v("max_line_spread", max_line_spread);
    v("query_spacing_m", query_spacing_m);
    v("max_correspondence_m", max_correspondence_m);
    v("final_correspondence_m", final_correspondence_m);
    v("kernel_m", kernel_m);
    v("max_iterations", max_iterations);
    v("convergence_m", convergence_m);
    v("convergence_rad", convergence_rad);
    v("prior_sigma_xy_m", prior_sigma_xy_m);
    v("prior_sigma_theta_rad", prior_sigma_theta_rad);
    v("min_residual_sigma_m", min_residual_sigma_m);
    v("min_inlier_fraction", min_inlier_fraction);
    v("min_valid_points", min_valid_points);
  }
};

std::optional<std::string> validate(const IcpConfig& config);

}  // namespace traverse::frontend
