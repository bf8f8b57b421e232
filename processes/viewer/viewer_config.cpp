#include "viewer_config.hpp"

#include "config.hpp"

namespace traverse::viewer {

std::optional<std::string> validate(const ViewerConfig& c) {
  ConfigCheck check;
  check.not_empty("address", c.address);
  check.in_range("port", c.port, 0, 65535);
  check.not_empty("preview_channel", c.preview_channel);
  check.not_empty("segments_channel", c.segments_channel);
  check.not_empty("annotations_channel", c.annotations_channel);
  check.not_empty("pose_channel", c.pose_channel);
  check.not_empty("status_prefix", c.status_prefix);
  check.in_range("update_period_s", c.update_period_s, 0.01, 10.0);
  check.in_range("redraw_period_s", c.redraw_period_s, 0.0, 10.0);
  check.in_range("trajectory_step_m", c.trajectory_step_m, 0.0, 10.0);
  check.in_range("pose_history_s", c.pose_history_s, 1.0, 3600.0);
  check.in_range("loop_min_age_s", c.loop_min_age_s, 0.0, 86400.0);
  // A snapshot of a large cloud must fit in a queue, or a browser could never catch up.
  check.in_range("client_queue_bytes", c.client_queue_bytes, int64_t{1} << 20, int64_t{1} << 32);
  check.in_range("max_points", c.max_points, 1, 100'000'000);
  check.in_range("voxel_m", c.voxel_m, 0.01, 10.0);
  return check.problem();
}

}  // namespace traverse::viewer
