// Feeds one step of a synthetic drive (synthetic.hpp) to nodes on a bus, as the drivers and the
// frontend would: the horizontal scan on SCAN_HORIZONTAL, then the frontend's pose on
// POSE_FRONTEND.
#pragma once

#include <cstddef>
#include <cstdint>

#include "bus.hpp"
#include "channels.hpp"
#include "scan_message.hpp"
#include "synthetic.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::backend::test {

// late: the pose is flagged pose2d_t::FLAG_LATE and lies 0.3 rad back (a scan stamped late).
inline void publish_drive_step(Bus& bus, const Drive& d, std::size_t k, bool late = false) {
  const auto seq = static_cast<int64_t>(k);
  planar_scan_t scan = to_planar_scan_message(d.scans[k], "laser_horizontal", seq);
  bus.publish(channels::kScanHorizontal, scan);
  pose2d_t p{};
  p.utime = d.utimes[k];
  p.seq = seq;
  p.parent_frame = "map";
  p.child_frame = "base";
  p.x = d.input[k].x();
  p.y = d.input[k].y();
  p.theta = d.input[k].theta() - (late ? 0.3 : 0.0);
  p.flags = late ? pose2d_t::FLAG_LATE : 0;
  bus.publish(channels::kPoseFrontend, p);
}

}  // namespace traverse::backend::test
