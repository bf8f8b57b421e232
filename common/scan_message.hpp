// Conversion between the planar_scan_t message and the LCM-free PlanarScan the libraries take.
#pragma once

#include <string>

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

// The message of a scan (utime = its first beam's time), e.g. for feeding a node in tests.
inline planar_scan_t to_planar_scan_message(const PlanarScan& scan, const std::string& frame,
                                            int64_t seq = 0) {
  planar_scan_t msg{};
  msg.utime = scan.utime_first;
  msg.seq = seq;
  msg.frame = frame;
  msg.utime_first = scan.utime_first;
  msg.utime_last = scan.utime_last;
  msg.angle_first = static_cast<float>(scan.angle_first);
  msg.angle_step = static_cast<float>(scan.angle_step);
  msg.range_min = static_cast<float>(scan.range_min);
  msg.range_max = static_cast<float>(scan.range_max);
  msg.ranges = scan.ranges;
  msg.n_ranges = static_cast<int32_t>(scan.ranges.size());
  return msg;
}

}  // namespace traverse
