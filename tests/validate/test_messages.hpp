// Messages and raw bytes for the validate tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "traverse/imu_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::test {

template <class T>
std::vector<uint8_t> encode(const T& msg) {
  std::vector<uint8_t> buf(msg.getEncodedSize());
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

inline pose2d_t make_pose(int64_t utime, int64_t seq) {
  pose2d_t p{};
  p.utime = utime;
  p.seq = seq;
  p.parent_frame = "world";
  p.child_frame = "base";
  return p;
}

inline planar_scan_t make_scan(int64_t utime, int64_t seq, int n_ranges, int64_t sweep_us = 0) {
  planar_scan_t s{};
  s.utime = utime;
  s.seq = seq;
  s.frame = "laser_horizontal";
  s.utime_first = utime;
  s.utime_last = utime + sweep_us;
  s.angle_first = -1.5708f;
  s.angle_step = 0.0174533f;
  s.range_min = 0.1f;
  s.range_max = 40.0f;
  s.n_ranges = n_ranges;
  s.ranges.assign(n_ranges, 2.0f);
  s.n_intensities8 = 0;
  s.n_intensities16 = 0;
  return s;
}

inline imu_t make_imu(int64_t utime, int64_t seq) {
  imu_t m{};
  m.utime = utime;
  m.seq = seq;
  m.frame = "imu";
  return m;
}

}  // namespace traverse::test
