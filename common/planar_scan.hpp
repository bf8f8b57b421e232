// One sweep of a planar scanner as the algorithms see it: planar_scan_t without the transport
// fields, so libraries that must not include LCM can take scans. Beam i is measured at
// utime_first + i * (utime_last - utime_first) / (n - 1) along angle_first + i * angle_step in
// the scanner's frame.
#pragma once

#include <cstdint>
#include <vector>

namespace traverse {

struct PlanarScan {
  int64_t utime_first = 0;    // [us]
  int64_t utime_last = 0;     // [us]
  double angle_first = 0.0;   // [rad] in the scanner frame
  double angle_step = 0.0;    // [rad]
  double range_min = 0.0;     // [m]
  double range_max = 0.0;     // [m]
  std::vector<float> ranges;  // [m]; NaN, 0 or outside [range_min, range_max]: no return
};

}  // namespace traverse
