// LCM channel names, defined once. A producer never knows its consumers; any process may listen.
#pragma once

#include <string>

namespace traverse::channels {

inline const std::string kScanHorizontal = "SCAN_HORIZONTAL";  // planar_scan_t, horizontal scanner
inline const std::string kScanProfile = "SCAN_PROFILE";        // planar_scan_t, tilted scanner
inline const std::string kImu = "IMU";                         // imu_t
inline const std::string kOdometry = "ODOMETRY";               // odometry_t, wheel encoders
inline const std::string kPoseGroundTruth = "POSE_GROUND_TRUTH";  // pose2d_t, simulator truth
inline const std::string kPoseGroundTruth3d =
    "POSE_GROUND_TRUTH_3D";                                  // pose3d_t, the same in 6-DoF
inline const std::string kPoseReference = "POSE_REFERENCE";  // pose2d_t, external reference
inline const std::string kPoseFrontend = "POSE_FRONTEND";    // pose2d_t, one per scan
inline const std::string kKeyPoses = "KEY_POSES";  // key_poses_t, backend key poses (incremental)
inline const std::string kPoseGraphEdges =
    "POSE_GRAPH_EDGES";  // pose_graph_edges_t, backend graph edges (appended)
inline const std::string kAnnotations =
    "ANNOTATIONS";  // annotations_t, 95 % bounds, accuracy levels, colours
inline const std::string kPoseBackend = "POSE_BACKEND";      // pose2d_t, each backend key pose once
inline const std::string kPoseDense = "POSE_DENSE";          // pose2d_t, corrected dense trajectory
inline const std::string kDenseSegments = "DENSE_SEGMENTS";  // dense_segments_t, new or moved
inline const std::string kFrontendControl =
    "FRONTEND_CONTROL";  // frontend_control_t, which frontend runs (operator's requests)
inline const std::string kCloudPreview =
    "CLOUD_PREVIEW";  // cloud_preview_t, the mapper's decimated points for screens
inline const std::string kResendRequest =
    "RESEND_REQUEST";  // resend_request_t, a late listener asks for the whole state of channels

// LCM's udpm provider sends one message here when an instance starts: not part of any run.
inline const std::string kLcmSelfTest = "LCM_SELF_TEST";

// Where the whole state behind an incremental channel is published once more when a late
// listener asks for it (resend_request_t on RESEND_REQUEST, common/resend.hpp): <channel>_FULL,
// as KEY_POSES_FULL, with the incremental channel's type.
std::string full_channel(const std::string& channel);

// Every process publishes process_status_t once a second on STATUS_<NAME> (name upper-cased).
std::string status_channel(const std::string& process_name);

}  // namespace traverse::channels
