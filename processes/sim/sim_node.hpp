// Adapts simulator events to LCM messages: planar_scan_t on SCAN_HORIZONTAL and SCAN_PROFILE,
// imu_t on IMU, pose2d_t (world -> base, zero covariance) on POSE_GROUND_TRUTH with pose3d_t on
// POSE_GROUND_TRUTH_3D, odometry_t (odom -> base) on ODOMETRY.
#pragma once

#include "publisher.hpp"
#include "simulator.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "traverse/pose3d_t.hpp"

namespace traverse::sim {

planar_scan_t to_message(const ScanData& scan);
imu_t to_message(const ImuData& imu);
pose2d_t to_message(const GroundTruth& gt);
pose3d_t to_message_3d(const GroundTruth& gt);
odometry_t to_message(const OdometryData& odom);

// Publishes one event on its channel; the ground truth also as pose3d_t when `publish_3d` (the
// ideal profile's logs stay as they were).
void publish_event(Publisher& publisher, const SimEvent& ev, bool publish_3d);

}  // namespace traverse::sim
