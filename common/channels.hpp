// LCM channel names, defined once. A producer never knows its consumers; any process may listen.
#pragma once

#include <string>

namespace traverse::channels {

inline const std::string kScanHorizontal = "SCAN_HORIZONTAL";  // planar_scan_t, horizontal scanner
inline const std::string kScanProfile = "SCAN_PROFILE";        // planar_scan_t, tilted scanner
inline const std::string kImu = "IMU";                         // imu_t
inline const std::string kPoseGroundTruth = "POSE_GROUND_TRUTH";  // pose2d_t, simulator truth
inline const std::string kPoseReference = "POSE_REFERENCE";    // pose2d_t, external reference
inline const std::string kPoseFrontend = "POSE_FRONTEND";      // pose2d_t, one per scan

// Every process publishes process_status_t once a second on STATUS_<NAME> (name upper-cased).
std::string status_channel(const std::string& process_name);

}  // namespace traverse::channels
