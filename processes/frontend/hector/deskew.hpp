// Motion compensation of one sweep (seed 000 section 2): each point, measured at its own time
// t_i, is moved into the base frame at the reference time t_ref (the scan's last point) using the
// heading change between the two times and, optionally, the translation of constant velocity.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "motion_model.hpp"

namespace traverse::frontend {

// heading_change(t) is the base's heading at t minus its heading at utime_ref [rad];
// velocity_base is the base's linear velocity [m/s] in its own frame at utime_ref.
void deskew_points(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
                   int64_t utime_ref, const std::function<double(int64_t)>& heading_change,
                   const Eigen::Vector2d& velocity_base, bool translation);

// deskew_points() with the motion model's heading change (the IMU's when use_imu, else its
// angular velocity) and velocity.
void deskew_sweep(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
                  int64_t utime_ref, const MotionModel& motion, bool use_imu, bool translation);

}  // namespace traverse::frontend
