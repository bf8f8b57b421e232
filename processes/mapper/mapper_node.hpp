// Adapts LCM messages to the Mapper: tilted profiles (planar_scan_t on SCAN_PROFILE) and the
// corrected trajectory in, exports out. The trajectory comes either as whole segments from the
// densifier (dense_segment_t on DENSE_SEGMENT; a moved segment arrives again with an earlier
// utime, so that channel accepts out-of-order messages) or, with `pose_channel` set, as a plain
// pose2d_t stream (e.g. POSE_GROUND_TRUTH) cut into segments of `poses_per_segment` poses that
// never move.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "bus.hpp"
#include "mapper.hpp"
#include "traverse/dense_segment_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::mapper {

class MapperNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  MapperNode(Bus& bus, const MapperConfig& config, const Eigen::Isometry3d& T_base_laser,
             CounterSink counters = {});

  // Applies pending moves and drops profiles that waited too long (call from the loop).
  void tick();
  // Writes cloud.ply, map.bt and map.ot into the output folder; false (and why) on failure.
  bool export_all(std::string* error);
  // At shutdown: closes the last segment of a pose2d_t stream, applies moves.
  void finish();
  void report_counters();
  const Mapper& mapper() const { return mapper_; }

 private:
  void on_profile(const planar_scan_t& msg);
  void on_segment(const dense_segment_t& msg);
  void on_pose(const pose2d_t& msg);
  void cut_segment();

  MapperConfig config_;
  Mapper mapper_;
  CounterSink counters_;
  int64_t latest_utime_ = 0;
  double rejected_ = 0, dropped_ = 0;
  TrajectorySegment open_;  // pose2d_t stream: poses since the last cut
  int64_t next_key_id_ = 0;
};

}  // namespace traverse::mapper
