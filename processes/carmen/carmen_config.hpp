// Settings of the CARMEN log driver: every key with its default and meaning (configs/carmen.yaml
// holds what a deployment sets).
#pragma once

#include <optional>
#include <string>

#include "odometry.hpp"

namespace traverse::carmen {

struct CarmenConfig {
  // Reading of FLASER beam angles: standard, half_open, closed, centered, reversed (see
  // carmen_log.hpp); standard gives the sharpest maps on the Radish logs.
  std::string flaser_geometry = "standard";
  // [m] Readings outside [range_min_m, range_max_m] are no return. Real returns of the Radish
  // logs' scanners stay below 50 m.
  double range_min_m = 0.05;
  double range_max_m = 49.9;
  // [m] The log's no-return code: readings at or above it are no return. 0: found in the data,
  // as the largest value at least no_return_min_fraction of all beams hold exactly (aces 50.00,
  // intel 81.83, csail and freiburg 81.91; see no_return.hpp).
  double no_return_code_m = 0.0;
  double no_return_min_fraction = 0.001;
  // Most beams published per scan: a scan with more is thinned to every k-th beam (counted), so
  // that no line of a log costs the graph unbounded time (a CARMEN scanner has at most 1,081).
  int max_beams = 4096;
  // [s] Stamps printed coarser than this carry no time (csail prints 1.13486e+09: 1e4 s steps).
  // When neither the ipc nor the logger stamps of a log's scans carry time (also: all equal,
  // negative, out of order), scans are placed nominal_scan_period_s apart, as a log subsampled by
  // travel: longer than the frontend's matcher.wide_search_gap_us (0.5 s), so it treats them as
  // sparse (log_time.hpp).
  double max_timestamp_quantum_s = 1.0;
  double nominal_scan_period_s = 3.0;
  // Where odometry_t on ODOMETRY comes from: auto (the ODOM lines when the log has any, else the
  // laser lines' odometry fields), odom, laser, none. A corrected log's laser lines carry the
  // corrected pose in their odometry fields: do not name `laser` for such a log.
  std::string odometry_source = "auto";
  // CARMEN states no odometry covariance: the driver's model (odometry.hpp).
  OdometryNoise odometry_noise;

  template <class V>
  void visit(V& v) {
    v("flaser_geometry", flaser_geometry);
    v("range_min_m", range_min_m);
    v("range_max_m", range_max_m);
    v("no_return_code_m", no_return_code_m);
    v("no_return_min_fraction", no_return_min_fraction);
    v("max_beams", max_beams);
    v("max_timestamp_quantum_s", max_timestamp_quantum_s);
    v("nominal_scan_period_s", nominal_scan_period_s);
    v("odometry_source", odometry_source);
    v("odometry_noise", odometry_noise);
  }
};

// The one place a config is checked: the first problem, naming its key, or nullopt.
std::optional<std::string> validate(const CarmenConfig& config);

}  // namespace traverse::carmen
