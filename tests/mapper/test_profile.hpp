// A tilted profile message for the mapper's tests: 360 beams over a full turn, 30 ms long.
#pragma once

#include <cstdint>
#include <numbers>
#include <vector>

#include "traverse/planar_scan_t.hpp"

namespace traverse {

inline planar_scan_t test_profile(int64_t t0, std::vector<float> ranges) {
  planar_scan_t s{};
  s.utime = s.utime_first = t0;
  s.utime_last = t0 + 30'000;
  s.frame = "laser_profile";
  s.angle_first = static_cast<float>(-std::numbers::pi);
  s.angle_step = static_cast<float>(2 * std::numbers::pi / 360);
  s.range_min = 0.6f;
  s.range_max = 6.0f;
  s.ranges = std::move(ranges);
  s.n_ranges = static_cast<int32_t>(s.ranges.size());
  return s;
}

}  // namespace traverse
