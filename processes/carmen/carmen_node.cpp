#include "carmen_node.hpp"

#include <algorithm>
#include <iterator>

#include "channels.hpp"
#include "config.hpp"
#include "se2.hpp"

namespace traverse::carmen {

std::optional<std::string> validate(const CarmenConfig& c) {
  ConfigCheck check;
  check.require(
      parse_flaser_geometry(c.flaser_geometry).has_value(), "flaser_geometry",
      "must be standard, half_open, closed, centered or reversed, not '" + c.flaser_geometry + "'");
  check.not_negative("range_min_m", c.range_min_m);
  check.require(c.range_max_m > c.range_min_m, "range_max_m", "must exceed range_min_m");
  check.in_range("max_timestamp_quantum_s", c.max_timestamp_quantum_s, 1e-6, 1e9);
  check.in_range("nominal_scan_period_s", c.nominal_scan_period_s, 1e-6, 3600.0);
  return check.problem();
}

planar_scan_t to_scan_message(const Scan& scan, const CarmenConfig& cfg) {
  planar_scan_t msg{};
  msg.utime = scan.utime;
  msg.frame = kLaserFrame;
  msg.utime_first = scan.utime;
  msg.utime_last = scan.utime;
  msg.angle_first = static_cast<float>(scan.beams.angle_first);
  msg.angle_step = static_cast<float>(scan.beams.angle_step);
  msg.range_min = static_cast<float>(cfg.range_min_m);
  msg.range_max = static_cast<float>(std::min(cfg.range_max_m, scan.range_max_m.value_or(1e9)));
  msg.n_ranges = static_cast<int32_t>(scan.ranges.size());
  msg.ranges = scan.ranges;
  msg.n_intensities8 = 0;
  msg.n_intensities16 = 0;
  return msg;
}

pose2d_t to_reference_pose(const Scan& scan) {
  pose2d_t msg{};
  msg.utime = scan.utime;
  msg.parent_frame = "world";
  msg.child_frame = "base";
  msg.x = scan.x_m;
  msg.y = scan.y_m;
  msg.theta = wrap_angle(scan.theta_rad);
  std::fill(std::begin(msg.covariance), std::end(msg.covariance), 0.0);  // unknown
  msg.flags = 0;
  return msg;
}

void publish_scan(Publisher& out, const Scan& scan, const CarmenConfig& cfg) {
  planar_scan_t scan_msg = to_scan_message(scan, cfg);
  out.publish(channels::kScanHorizontal, scan_msg);
  pose2d_t pose_msg = to_reference_pose(scan);
  out.publish(channels::kPoseReference, pose_msg);
}

}  // namespace traverse::carmen
