// A cart pushed by a person: between stops it rolls along straight lines joined by arcs (corners
// are driven while moving, not stopped at and turned on the spot), at a speed that wanders about
// the cruise speed, slows where the arc is tight (lateral acceleration limit) and starts and stops
// at the platform's acceleration; the line weaves a few cm from side to side. A stop (a pause the
// route asks for, or a reversal, which is turned on the spot) ends one run and starts the next.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "effects.hpp"
#include "rng.hpp"
#include "se2.hpp"

namespace traverse::sim {

// One piece of a run's path: a line (radius 0) or an arc (signed curvature 1/radius).
struct PathPiece {
  Pose2 start;           // pose at the piece's start (heading along the path)
  double length = 0.0;   // [m]
  double curvature = 0;  // [1/m], positive turning left
};

// One continuous drive from standstill to standstill.
class PushedRun {
 public:
  // Throws std::runtime_error for an empty path. `rng` draws the speed and weave phases. The cart
  // starts turned by start_yaw_rad from the path and rolls back onto it over
  // motion.start_settle_m (a lateral lead-in y = tan(yaw) s (1 - s / L)^2 on top of the weave).
  PushedRun(std::vector<PathPiece> pieces, double cruise_mps, double accel_mps2,
            const MotionEffect& motion, Rng& rng, double start_yaw_rad = 0.0);

  double duration_s() const { return t_.back(); }
  double length_m() const { return length_; }
  // Pose, travelled distance [m] and speed [m/s] tau [s] after the run's start.
  void at(double tau, Pose2& pose, double& s, double& v) const;
  // Pose at path parameter s [m], weave included.
  Pose2 pose_at(double s) const;

 private:
  Pose2 centre_line(double s, double& curvature) const;
  double weave(double s, double& slope) const;

  std::vector<PathPiece> pieces_;
  std::vector<double> piece_s0_;  // [m] path parameter at each piece's start
  double length_ = 0.0;
  double ds_ = 0.02;           // [m] grid of the speed profile
  std::vector<double> v_, t_;  // [m/s], [s] at s = k * ds_
  double weave_amp_[2] = {0, 0}, weave_k_[2] = {0, 0}, weave_phase_[2] = {0, 0};
  double lead_in_slope_ = 0.0;  // tan of the start yaw
  double lead_in_m_ = 1.0;      // [m] L
};

// The corner arcs of a polyline: pieces from p[0] to p.back() with every interior corner turned
// on an arc of radius at most `max_radius` (less where the legs are short).
std::vector<PathPiece> fillet_polyline(const std::vector<Eigen::Vector2d>& p, double max_radius);

}  // namespace traverse::sim
