// Settings of the CARMEN log driver.
#pragma once

#include <optional>
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
  // [s] Timestamps printed coarser than this are quantised (csail prints 1.13486e+09: 1e4 s
  // steps; whole seconds still order scans that come every few seconds). Such scans take the logger
  // timestamp if it is printed finely, else they are spaced nominal_scan_period_s apart (the Radish
  // logs' subsampled scans come about every 3 s: intel 2.9 s, aces 3.0 s). The frontend treats
  // scans over 0.5 s apart as sparse.
  double max_timestamp_quantum_s = 1.0;
  double nominal_scan_period_s = 3.0;

  template <class V>
  void visit(V& v) {
    v("flaser_geometry", flaser_geometry);
    v("range_min_m", range_min_m);
    v("range_max_m", range_max_m);
    v("max_timestamp_quantum_s", max_timestamp_quantum_s);
    v("nominal_scan_period_s", nominal_scan_period_s);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const CarmenConfig& config);

}  // namespace traverse::carmen
