// Adapts simulator events to LCM messages: planar_scan_t on SCAN_HORIZONTAL and SCAN_PROFILE,
// imu_t on IMU, pose2d_t (world -> base, zero covariance) on POSE_GROUND_TRUTH.
#pragma once

#include "publisher.hpp"
#include "simulator.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::sim {

planar_scan_t to_message(const ScanData& scan);
imu_t to_message(const ImuData& imu);
pose2d_t to_message(const GroundTruth& gt);

// Publishes one event on its channel.
void publish_event(Publisher& publisher, const SimEvent& ev);

}  // namespace traverse::sim
