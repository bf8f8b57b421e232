// Conversion of the planar_scan_t message into the LCM-free PlanarScan the libraries take.
#pragma once

#include "planar_scan.hpp"
#include "traverse/planar_scan_t.hpp"

namespace traverse {

inline PlanarScan to_planar_scan(const planar_scan_t& msg) {
  PlanarScan scan;
  scan.utime_first = msg.utime_first;
  scan.utime_last = msg.utime_last;
  scan.angle_first = msg.angle_first;
  scan.angle_step = msg.angle_step;
  scan.range_min = msg.range_min;
  scan.range_max = msg.range_max;
  scan.ranges = msg.ranges;
  return scan;
}

}  // namespace traverse
