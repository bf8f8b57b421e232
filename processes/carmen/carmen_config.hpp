// Settings of the CARMEN log driver.
#pragma once

#include <string>

namespace traverse::carmen {

struct CarmenConfig {
  // Reading of FLASER beam angles: standard, half_open, closed, centered, reversed (see
  // carmen_log.hpp); standard gives the sharpest maps on the Radish logs.
  std::string flaser_geometry = "standard";
  // [m] Readings outside [range_min_m, range_max_m] are no return. The Radish logs mark no return
  // with 50.0 (aces), 81.83 (intel) or 81.91 (csail, freiburg); real returns stay below 50 m.
  double range_min_m = 0.05;
  double range_max_m = 49.9;

  template <class V>
  void visit(V& v) {
    v("flaser_geometry", flaser_geometry);
    v("range_min_m", range_min_m);
    v("range_max_m", range_max_m);
  }
};

}  // namespace traverse::carmen
