// A planar pose in a config: an extrinsic (T_base_laser) or a pose in a site's frame
// (initial_pose), keys x_m, y_m, theta_rad.
#pragma once

#include <cmath>
#include <optional>
#include <string>

#include "config.hpp"
#include "se2.hpp"

// In a namespace of its own: a config's validate() is found by argument-dependent look-up, and
// namespace traverse already has a namespace named validate (the log checks).
namespace traverse::configs {

struct Pose2Config {
  double x_m = 0.0;        // [m]
  double y_m = 0.0;        // [m]
  double theta_rad = 0.0;  // [rad]

  Pose2 pose() const { return Pose2(x_m, y_m, theta_rad); }

  template <class V>
  void visit(V& v) {
    v("x_m", x_m);
    v("y_m", y_m);
    v("theta_rad", theta_rad);
  }
};

// x and y within 1000 km (a site frame's extent; farther, a map's cell indices overflow), theta
// within +-2 pi.
inline std::optional<std::string> validate(const Pose2Config& c) {
  ConfigCheck check;
  check.in_range("x_m", c.x_m, -1e6, 1e6);
  check.in_range("y_m", c.y_m, -1e6, 1e6);
  check.in_range("theta_rad", c.theta_rad, -2.0 * M_PI, 2.0 * M_PI);
  return check.problem();
}

}  // namespace traverse::configs

namespace traverse {
using configs::Pose2Config;
}  // namespace traverse
