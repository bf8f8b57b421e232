// The floor as the cart's wheels feel it, and the attitude it gives the cart. The floor's height
// above the world's floor plane is the sum of
// - tiles: square tiles (world file, tile_size_m) each set a little high or low (lippage), so a
//   wheel steps by a few mm at every joint, climbing it over joint_ramp_m (smootherstep, so the
//   cart's accelerations stay finite);
// - door thresholds: raised strips with bevelled edges across doorways (10-20 mm);
// - ramps: gentle humps (about 0.5 deg) that return to the floor plane.
// A rigid cart on four wheels (wheelbase x track) takes the mean height of its wheels and pitches
// and rolls by the height differences between its axles and sides. The scanners' beams still meet
// the plane floor_z: the floor model moves the cart, not the floor the scanners see (a few mm,
// and a threshold's 15 mm strip, are below what this simulator draws as geometry).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "effects.hpp"
#include "se2.hpp"
#include "world_spec.hpp"

namespace traverse::sim {

// Roll and pitch [rad] of the base frame (R = Rz(yaw) Ry(pitch) Rx(roll)) and the height [m] of
// its origin above the floor plane.
struct CartAttitude {
  double z = 0.0, roll = 0.0, pitch = 0.0;
};

class FloorModel {
 public:
  // Throws std::runtime_error for unusable threshold or ramp geometry.
  FloorModel(const FloorSpec& spec, const FloorEffect& effect, double half_track_m, uint64_t seed);

  // [m] floor height above the floor plane at world (x, y).
  double height(const Eigen::Vector2d& p) const;
  // The cart's attitude at the planar pose T_world_base.
  CartAttitude attitude(const Pose2& T_world_base) const;

 private:
  double tile_offset(int64_t i, int64_t j) const;
  double tiles(const Eigen::Vector2d& p) const;

  FloorSpec spec_;
  FloorEffect effect_;
  double half_track_m_;
  uint64_t seed_;
};

// 6 t^5 - 15 t^4 + 10 t^3 on [0, 1], 0 below, 1 above: C2-smooth step.
double smootherstep(double t);

}  // namespace traverse::sim
