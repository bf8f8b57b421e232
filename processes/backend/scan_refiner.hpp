// Sub-centimetre refinement of a correlative match by point-to-line Gauss-Newton.
//
// The correlative search (correlative_matcher.hpp) finds the best pose on a grid of 2 cm and a few
// milliradians: robust, but its quantisation and its blurred table leave millimetre-level biases
// that add up along a chain of links and spoil a loop closure. This step starts from that pose and
// minimises the distances of the query points to the lines through the reference points (each
// reference point gets a normal from its neighbours; points in clutter or at corners, whose
// neighbours do not lie on a line, get none and are not used). Each query point is paired with
// the nearest reference point anew every iteration; pairs whose point-to-line distance exceeds
// three RMS residuals of the previous iteration are left out, and a Huber weight limits the pull
// of points the reference does not see the same way (moving people, new occlusions).
//
// Covariance: sigma^2 (J^T W J)^-1 with sigma^2 the weighted residual variance, multiplied by
// `covariance_scale` because neighbouring points share their errors (the same wall, the same
// reference scan), which the independent-point formula ignores. It has the same shape as the
// correlative one: wide along a corridor axis, narrow across it.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::backend {

struct RefinerConfig {
  bool enabled = true;
  double normal_radius_m = 0.15;       // reference neighbours within this fit the line [m]
  double max_line_thickness = 0.1;     // smallest / largest spread of those neighbours (0..1)
  double max_correspondence_m = 0.08;  // nearest reference point within this is the partner [m]
  double min_line_gate_m = 0.01;       // point-to-line distances beyond 3 RMS residuals of the last
                                  // iteration are not used, but this many metres always are [m]
  double huber_m = 0.005;  // residuals beyond this are down-weighted [m]
  int iterations = 15;
  double min_inlier_fraction = 0.3;  // fewer query points with a correspondence: not refined
  double max_shift_m = 0.05;         // a refinement farther than this from the start is refused
  double max_turn_rad = 0.02;        // [rad]
  double covariance_scale = 10.0;    // see above [unitless]

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("normal_radius_m", normal_radius_m);
    v("max_line_thickness", max_line_thickness);
    v("max_correspondence_m", max_correspondence_m);
    v("min_line_gate_m", min_line_gate_m);
    v("huber_m", huber_m);
    v("iterations", iterations);
    v("min_inlier_fraction", min_inlier_fraction);
    v("max_shift_m", max_shift_m);
    v("max_turn_rad", max_turn_rad);
    v("covariance_scale", covariance_scale);
  }
};

// An error message when a value is out of range, empty when the config is valid.
std::optional<std::string> validate(const RefinerConfig& config);

struct RefineResult {
  bool valid = false;   // false: too few correspondences, or it moved too far
  Pose2 T_world_query;  // refined pose (the start pose when not valid)
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // world frame: m^2, m rad, rad^2
  double rms_residual_m = 0.0;   // [m] weighted RMS point-to-line distance at the end
  double inlier_fraction = 0.0;  // query points with a correspondence at the end [0..1]
  // The information behind `covariance` without the floor its unconstrained directions are
  // raised to (covariance^-1 where every direction is constrained; world frame), and the lever
  // [m] the heading is weighed at (the query points' RMS range): common/degeneracy.hpp tells
  // from them which directions the scans leave open.
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  double lever_m = 1.0;
  int iterations = 0;
};

class ScanRefiner {
 public:
  // The config must pass validate().
  explicit ScanRefiner(RefinerConfig config) : config_(std::move(config)) {}

  RefineResult refine(const std::vector<Eigen::Vector2d>& reference_world,
                      const std::vector<Eigen::Vector2d>& query, const Pose2& T_world_start) const;

  const RefinerConfig& config() const { return config_; }

 private:
  RefinerConfig config_;
};

}  // namespace traverse::backend
