// Directions of a pose that a scan match does not determine, and the pose and covariance once the
// motion prior holds them (Zhang, Kaess and Singh 2016, "On degeneracy of optimization-based state
// estimation problems": the weak eigen-directions of the Gauss-Newton Hessian; their "solution
// remapping" keeps the prior's value there and the match's elsewhere).
//
// The scan's information I (x [m], y [m], theta [rad]; the Gauss-Newton Hessian scaled as the
// covariance is, without the matcher's weak prior) is compared in common units: heading as the arc
// it moves the matched points through, L theta with L the points' RMS distance from the base, so
// that with xi = S xi', xi' = (x, y, L theta), S = diag(1, 1, 1/L), I' = S I S is per square
// metre of point motion in every direction. Its eigen-directions
// v with eigenvalue lambda below min_ratio times the largest are degenerate: along a bare
// corridor's axis the walls give nothing, and what the map's history gives there (a wall's cells
// ending where the map has seen it so far, people it took in) is not to be trusted over the motion
// prior. The pose then takes the match's displacement from the prediction only along the other
// directions (xi = xi_pred + P (xi_match - xi_pred), P the projector onto them), and its covariance
// is the match's there and the prediction's along the degenerate directions: a corridor's axis
// comes out with the variance the motion prior has grown to, not the millimetres the map's history
// claims. Used by the Hector frontend (its scan-to-map match) and by the backend (its links between
// key scans, backend.hpp).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "se2.hpp"

namespace traverse {

struct Degeneracy {
  int directions = 0;  // degenerate eigen-directions (0: the match determines the whole pose)
  // Smallest over largest eigenvalue of I' (see the header), 0 to 1.
  double ratio = 1.0;
  // Projector onto the well-determined directions, in (x, y, theta): xi_pred + P (xi - xi_pred).
  Eigen::Matrix3d projector = Eigen::Matrix3d::Identity();
  // The eigen-directions of I' (columns, unit length in (x, y, L theta)) and their eigenvalues
  // [1/m^2], ascending.
  Eigen::Matrix3d directions_scaled = Eigen::Matrix3d::Identity();
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
  double length_m = 1.0;  // L
};

// L for a scan: the RMS distance of its matched points from the base [m] (1 m for no point, at
// least 1 mm).
double points_rms_range_m(const std::vector<Eigen::Vector2d>& points_base);

// information: the match's (3x3, symmetric, [1/m^2, 1/(m rad), 1/rad^2]); length_m: L [m] (> 0).
Degeneracy analyse_degeneracy(const Eigen::Matrix3d& information, double length_m,
                              double min_ratio);

// The pose: the match's displacement from the prediction along the well-determined directions
// only (heading wrapped).
Pose2 remap(const Degeneracy& d, const Pose2& T_predicted, const Pose2& T_matched);

// The covariance: the match's information along the well-determined directions, the
// prediction's covariance along the degenerate ones (each direction's variance from the
// prediction's covariance projected onto it; the two do not mix).
Eigen::Matrix3d remapped_covariance(const Degeneracy& d,
                                    const Eigen::Matrix3d& covariance_predicted);

// The covariance of a match held along the degenerate directions (remap): the match's own
// covariance along the well-determined ones, the prediction's along the degenerate ones (each
// projected onto its direction; the two do not mix).
Eigen::Matrix3d held_covariance(const Degeneracy& d, const Eigen::Matrix3d& covariance_matched,
                                const Eigen::Matrix3d& covariance_predicted);

// A covariance opened along the degenerate directions: each gets the variance its own
// information allows there (1 / lambda, in metres of point motion: over L^2 for the heading), at
// most sigma_m^2, on top; the others are left as they are. For a match whose own covariance does
// not see what its geometry leaves open (the backend's links: a correlative response surface is
// bounded by its search window).
Eigen::Matrix3d opened_covariance(const Degeneracy& d, const Eigen::Matrix3d& covariance,
                                  double sigma_m);

}  // namespace traverse
