// Conversion of the odometry_t message into the LCM-free OdometrySample the frontends take.
#pragma once

#include "frontend.hpp"
#include "traverse/odometry_t.hpp"

namespace traverse::frontend {

inline OdometrySample to_odometry_sample(const odometry_t& msg) {
  OdometrySample o;
  o.utime = msg.utime;
  o.T_odom_base = Pose2(msg.x, msg.y, msg.theta);
  for (int i = 0; i < 9; ++i)
    o.pose_covariance(i / 3, i % 3) = msg.pose_covariance[i];  // row-major
  return o;
}

}  // namespace traverse::frontend
