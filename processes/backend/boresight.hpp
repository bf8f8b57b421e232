// The horizontal scanner's boresight (its yaw on the cart) estimated from the backend's optimised
// key poses and applied to the whole trajectory the backend publishes.
//
// A scanner turned by delta on the cart against the rig file makes the frontend track the base
// turned by delta: the graph is consistent, but it comes out turned by delta about its first key
// pose (common/extrinsic_yaw.hpp says why no scan can show it and how the direction of travel of
// a wheeled base does). The frontend could turn each pose back as it publishes it
// (frontend calibration.extrinsic_yaw), but its estimate moves while it converges, and poses
// published with different estimates disagree with each other by (change of delta) x (distance
// from the start). Here the fit is made again on the key poses of every optimisation, and every
// key pose is published with that one estimate: positions turned by delta about the first key
// pose, headings as optimised (the map frame is the base at the first pose), covariances turned
// alike. The graph itself is left in the frame the scans were matched in (a rotation of the
// whole graph moves no edge). The densifier, which bends the frontend's dense trajectory onto the
// published key poses, follows.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "extrinsic_yaw.hpp"
#include "se2.hpp"

namespace traverse::backend {

struct BoresightConfig : calibration::ExtrinsicYawConfig {
  // Estimate and apply the yaw. Only for a platform that moves along its own x axis (a wheeled
  // cart), and only where the trajectory is wanted in the base's frame: a trajectory scored
  // against a reference made in the scanner's own frame (the CARMEN and relations logs) can only
  // get worse by it.
  bool enabled = false;
  // The estimate is applied only once it lies this many of its standard deviations from zero: a
  // rig file that is right is left as it is. On the ideal profile (no boresight error) an
  // estimate of 0.08 +- 0.59 mrad, applied, made office-s2 s1's 300 s 3.4 mm RMSE instead of
  // 1.0 mm; the realistic profile's 1.75-5.2 mrad lie 4.8-8.1 sigmas out after 300 s.
  double min_sigmas = 2.0;  // [unitless]

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("min_sigmas", min_sigmas);
    calibration::ExtrinsicYawConfig::visit(v);
  }
};

std::optional<std::string> validate(const BoresightConfig& config);

class Boresight {
 public:
  explicit Boresight(const BoresightConfig& config) : config_(config), estimator_(config) {}

  // Fits the yaw again on the key poses of an optimisation, T_world_base in time order.
  void update(const std::vector<Pose2>& key_poses);

  // The yaw applied [rad]: nullopt when off, or while the estimate does not hold (too little
  // travel, beyond max_yaw_rad, or within min_sigmas of zero).
  std::optional<double> yaw_rad() const { return yaw_; }
  // Its standard deviation [rad] (ExtrinsicYawEstimator::yaw_sigma_rad), while it is applied.
  double yaw_sigma_rad() const { return sigma_; }
  // The fit's estimate [rad], applied or not (0 before it holds).
  double estimate_rad() const { return estimator_.yaw_rad().value_or(0.0); }
  double travel_m() const { return estimator_.travel_m(); }
  long chords() const { return static_cast<long>(estimator_.chords()); }

  // A key pose as published: turned by the yaw about the first key pose (the pose unchanged while
  // no yaw is applied).
  Pose2 published(const Pose2& T_world_base, const Pose2& T_world_first) const;
  // A covariance of (x, y, theta) in the graph's frame, in the published frame.
  Eigen::Matrix3d published(const Eigen::Matrix3d& covariance) const;

 private:
  BoresightConfig config_;
  calibration::ExtrinsicYawEstimator estimator_;
  std::optional<double> yaw_;
  double sigma_ = 0.0;
};

}  // namespace traverse::backend
