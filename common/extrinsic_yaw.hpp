// The horizontal scanner's yaw in the base frame (its boresight), estimated from a trajectory
// tracked in the scanner's frame by the constraint of a wheeled platform: its base moves along its
// own x axis. Used by the frontend (calibration/, each pose as it comes) and by the backend
// (boresight.hpp, the whole key-pose trajectory after each optimisation).
//
// A frontend that takes the scanner's extrinsic from the rig file (T_base_laser) while the
// scanner is truly turned by delta on the cart (a hand calibration is off by 0.1-0.3 deg) tracks
// a frame bhat = the base turned by delta (T_base_bhat = Rot(delta)): its map and poses are
// consistent, but the whole trajectory comes out turned by delta about its start, a lateral
// error of delta times the distance from the start (0.3 deg: 0.26 m at 50 m), which no scan can
// show. The direction of travel does: the base moves along its heading, so in bhat's terms each
// chord of the path runs at -delta from the heading averaged along it (exactly so on an arc of
// constant curvature; where the curvature changes, to about the cube of the chord's turn). A
// point tracked a lever arm a ahead of the axle (a rig file's origin off the axle) adds a sideways
// slip of a times the turn: chord angle phi = -delta + a * kappa with kappa = turn / chord
// length. Both are fitted by weighted least squares over chords of chord_m (each weighted by the
// information of its angle, which grows with the chord's length squared), with weak priors that
// keep the fit defined before the path has turned (delta 0 +- 0.01 rad, a 0 +- 0.5 m); delta is
// what the estimate gives, a is fitted only so that turns do not bias it. Chords that turn more
// than 0.2 rad (a turn on the spot, a corner) or whose direction lies more than 0.2 rad from the
// heading (a glitch of the match, reversing) are left out. The estimate holds once min_travel_m
// of chords went in.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::calibration {

struct ExtrinsicYawConfig {
  double chord_m = 1.0;        // [m] path chords the fit takes
  double min_travel_m = 10.0;  // [m] of chords before the estimate holds
  double max_yaw_rad = 0.035;  // [rad] (2 deg) a larger estimate is not given: fix the rig file

  template <class V>
  void visit(V& v) {
    v("chord_m", chord_m);
    v("min_travel_m", min_travel_m);
    v("max_yaw_rad", max_yaw_rad);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const ExtrinsicYawConfig& config);

class ExtrinsicYawEstimator {
 public:
  explicit ExtrinsicYawEstimator(const ExtrinsicYawConfig& config);

  // A pose of the frame the trajectory tracks (bhat) in its map, in time order.
  void add_pose(const Pose2& T_map_bhat);
  // Forgets every pose (a trajectory that was re-estimated is fitted again from its start).
  void reset();

  // delta [rad] (T_base_bhat = Rot(delta)) once min_travel_m of chords went in, and within
  // +-max_yaw_rad; nullopt before (or beyond: a rig file off by more needs a new calibration).
  std::optional<double> yaw_rad() const;
  // The standard deviation of delta [rad]: the fit's, with the chords' angle noise taken from
  // their scatter about the fit where that is larger than the 5 mm a matched position is assumed
  // to carry (a pushed cart's weave, a matcher's slips).
  double yaw_sigma_rad() const;
  // The fitted lever arm a [m] of the tracked point ahead of the axle (see the header).
  double lever_arm_m() const { return solution().y(); }
  double travel_m() const { return travel_m_; }
  int64_t chords() const { return chords_; }
  int64_t chords_rejected() const { return rejected_; }

 private:
  Eigen::Vector2d solution() const;  // (delta [rad], a [m])
  Eigen::Matrix2d normal_matrix() const;

  void restart(const Pose2& T);  // a new chord from T

  ExtrinsicYawConfig config_;
  std::vector<Pose2> chord_;  // the poses of the current chord, from where it starts
  Eigen::Matrix2d A_ = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b_ = Eigen::Vector2d::Zero();
  double c_ = 0.0;  // sum of w phi^2, for the scatter about the fit
  double travel_m_ = 0.0;
  int64_t chords_ = 0, rejected_ = 0;
};

// The pose of the base for a pose of the tracked frame bhat, when the trajectory is turned back
// by the scanner's yaw delta about `origin` (the map position of the trajectory's first pose):
// T_map_base = T0 Rot(delta) T0^-1 T_map_bhat Rot(-delta), i.e. the position turned by delta
// about the first pose's, the heading as tracked (the map frame is the base at the first pose).
Pose2 turned_about(const Pose2& T_map_bhat, const Eigen::Vector2d& origin, double delta);

}  // namespace traverse::calibration
