// What every frontend of this process does the same way before matching: the IMU's orientation
// in the base frame from the config, the check that a sweep's times can be a planar scanner's,
// the count of samples taken and refused (hector/, icp/).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

#include "frontend.hpp"

namespace traverse::frontend {

// A sweep longer than this is not a sweep of a planar scanner: its times are wrong.
inline constexpr int64_t kMaxSweepUs = 1'000'000;

// R_base_imu = Rz(yaw) Ry(pitch) Rx(roll) of the config's deskew.imu_*_rad.
inline Eigen::Matrix3d R_base_imu(const DeskewConfig& c) {
  return (Eigen::AngleAxisd(c.imu_yaw_rad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(c.imu_pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c.imu_roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// The sweep ends before it starts or lasts longer than any planar scanner's, or does not come
// after `last_utime` (the last pose's, when there is one).
inline bool sweep_times_wrong(const Scan& scan, const int64_t* last_utime) {
  return scan.utime_last < scan.utime_first || scan.utime_last - scan.utime_first > kMaxSweepUs ||
         (last_utime && scan.utime_last <= *last_utime);
}

// Counts a sample as taken or refused; returns `taken`.
inline bool counted(bool taken, int64_t& taken_count, int64_t& refused_count) {
  ++(taken ? taken_count : refused_count);
  return taken;
}

}  // namespace traverse::frontend
