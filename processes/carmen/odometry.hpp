// Wheel odometry from a CARMEN log as a chain in a drifting frame of its own, with a covariance
// from a configured noise model (CARMEN logs state none).
//
// The chain moves by the motion between consecutive readings of the log's odometry, measured in
// the base frame of the earlier one, so that only the log's own increments enter it. This matters
// for the Radish "corrected" logs: after each scan, their ODOM lines restart from the corrected
// (reference) pose of that scan (an ODOM line repeating the scan's pose, stamped before it) and
// carry the raw increments from there. Taken as they are, they would hand the reference
// trajectory to whoever uses the odometry. reanchor() takes such a line: later motion is measured
// from it, the jump to it is not motion.
//
// Noise model: a random walk per distance travelled and angle turned, so that the covariance does
// not depend on how often the odometry was sampled. A step (dx, dy, dtheta) in the earlier base
// frame, of length d, adds the covariance diag(forward^2 d, lateral^2 d, heading_per_rad^2
// |dtheta| + heading_per_m^2 d) in that frame; the pose covariance is propagated through the
// composition (first order), in the odometry frame.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "se2.hpp"

namespace traverse::carmen {

struct OdometryNoise {
  double forward_m_per_sqrt_m = 0.05;      // [m/sqrt(m)] along-track error per sqrt(distance)
  double lateral_m_per_sqrt_m = 0.02;      // [m/sqrt(m)] cross-track error per sqrt(distance)
  double heading_rad_per_sqrt_rad = 0.05;  // [rad/sqrt(rad)] heading error per sqrt(turned)
  double heading_rad_per_sqrt_m = 0.02;    // [rad/sqrt(m)] heading error per sqrt(distance)
  // Standard deviations of a velocity the log states (ODOM tv and rv, ROBOTLASER1 tv and rv).
  double velocity_forward_mps = 0.05;  // [m/s]
  double velocity_lateral_mps = 0.01;  // [m/s] a differential drive does not slide
  double velocity_turn_radps = 0.05;   // [rad/s]

  template <class V>
  void visit(V& v) {
    v("forward_m_per_sqrt_m", forward_m_per_sqrt_m);
    v("lateral_m_per_sqrt_m", lateral_m_per_sqrt_m);
    v("heading_rad_per_sqrt_rad", heading_rad_per_sqrt_rad);
    v("heading_rad_per_sqrt_m", heading_rad_per_sqrt_m);
    v("velocity_forward_mps", velocity_forward_mps);
    v("velocity_lateral_mps", velocity_lateral_mps);
    v("velocity_turn_radps", velocity_turn_radps);
  }
};

std::optional<std::string> validate(const OdometryNoise& noise);

class OdometryChain {
 public:
  explicit OdometryChain(const OdometryNoise& noise) : noise_(noise) {}

  // A reading of the log's odometry, T_log_base in the log's odometry frame. The first starts the
  // chain at that pose with zero covariance; each later one moves it by the step from the
  // previous reading (or from the anchor set since).
  void add(const Pose2& T_log_base);
  // The log restarted its odometry at this pose: the next step is measured from here.
  void reanchor(const Pose2& T_log_base);

  bool started() const { return started_; }
  const Pose2& T_odom_base() const { return T_odom_base_; }
  // Of (x [m], y [m], theta [rad]) in the odometry frame: m^2, m*rad, rad^2.
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  double travel_m() const { return travel_m_; }  // [m] distance travelled along the chain

 private:
  OdometryNoise noise_;
  bool started_ = false;
  Pose2 T_odom_base_;
  Pose2 T_log_previous_;  // the log's last reading (or anchor)
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();
  double travel_m_ = 0.0;
};

// The covariance of a stated velocity (forward [m/s], left [m/s], turn [rad/s]): diagonal.
Eigen::Matrix3d velocity_covariance(const OdometryNoise& noise);

}  // namespace traverse::carmen
