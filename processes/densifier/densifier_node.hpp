// Adapts LCM messages to the Densifier: frontend poses (pose2d_t on POSE_FRONTEND) and optimised
// key poses in, corrected trajectory out. Key poses come from the backend's incremental
// key_poses_t messages (KEY_POSES: the key poses that appeared or moved in one optimisation, split
// into parts that share a utime, so that channel accepts repeated and out-of-order times).
// Out: every pose of a newly closed segment once on POSE_DENSE (pose2d_t, as the trajectory
// grows), and each new or moved segment whole on DENSE_SEGMENT (dense_segment_t).
#pragma once

#include <functional>
#include <string>

#include "bus.hpp"
#include "densifier.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::densifier {

class DensifierNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  DensifierNode(Bus& bus, const DensifierConfig& config, CounterSink counters = {});
  void report_counters();

 private:
  void on_frontend(const pose2d_t& msg);
  void on_key_poses(const key_poses_t& msg);
  void publish(const std::vector<Segment>& segments);

  Bus& bus_;
  DensifierConfig config_;
  Densifier densifier_;
  CounterSink counters_;
  std::string child_frame_ = "base";
  int64_t last_dense_published_utime_ = -1;
  double segments_published_ = 0, dense_rejected_ = 0;
};

}  // namespace traverse::densifier
