// Turns CARMEN scans into Traverse messages: each scan becomes a planar_scan_t on
// channels::kScanHorizontal (frame "laser_horizontal") and its logged pose a pose2d_t on
// channels::kPoseReference (T_world_base).
//
// Frames: CARMEN logs the pose of the laser. We take the base frame to be the horizontal laser's
// frame (T_base_laser = identity), so the logged pose is T_world_base; the Radish logs used here
// state a front-laser offset of 0 (intel, aces, csail) or 4 cm (freiburg), which this ignores.
// Time: CARMEN stamps a scan once, so utime_first = utime_last = that stamp; consumers must not
// read a sweep duration into it.
#pragma once

#include "carmen_config.hpp"
#include "carmen_log.hpp"
#include "publisher.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::carmen {

inline constexpr const char* kLaserFrame = "laser_horizontal";

planar_scan_t to_scan_message(const Scan& scan, const CarmenConfig& cfg);
pose2d_t to_reference_pose(const Scan& scan);

// Publishes both messages of one scan.
void publish_scan(Publisher& out, const Scan& scan, const CarmenConfig& cfg);

}  // namespace traverse::carmen
