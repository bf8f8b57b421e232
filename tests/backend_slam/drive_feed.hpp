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

inline void publish_drive_step(Bus& bus, const Drive& d, std::size_t k) {
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
  p.theta = d.input[k].theta();
  bus.publish(channels::kPoseFrontend, p);
}

}  // namespace traverse::backend::test
