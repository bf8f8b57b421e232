// Adapts LCM messages to the Densifier: frontend poses (pose2d_t on POSE_FRONTEND) and optimised
// key poses in, corrected trajectory out. Key poses come from the backend's incremental
// key_poses_t messages (KEY_POSES: the key poses that appeared or moved in one optimisation, split
// into parts that share a utime, so that channel accepts repeated and out-of-order times).
// Out: every pose of a newly closed segment once on POSE_DENSE (pose2d_t, as the trajectory
// grows), and the new or moved segments whole on DENSE_SEGMENTS (dense_segments_t), packed many to
// a message of at most `max_message_bytes`: after a loop closure hundreds of segments move at
// once, and one small datagram each overflowed the listeners' receive buffers. A listener that
// started late (the viewer) asks for every segment (common/resend.hpp: resend_request_t naming
// DENSE_SEGMENTS), and gets them on DENSE_SEGMENTS_FULL, the newest revision of each.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "bus.hpp"
#include "densifier.hpp"
#include "resend.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::densifier {

// Packs `segments` in order into messages of at most `max_bytes` encoded bytes each (a segment
// larger than that alone goes in a message of its own). Sets everything but utime and seq.
std::vector<dense_segments_t> pack_segments(const std::vector<Segment>& segments,
                                            const std::string& parent_frame,
                                            const std::string& child_frame, int32_t optimisation,
                                            int max_bytes);

class DensifierNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  DensifierNode(Bus& bus, const DensifierConfig& config, CounterSink counters = {});
  void report_counters();
  // End of data: sends every segment that moved at all since it was last sent.
  void finish();

 private:
  void on_frontend(const pose2d_t& msg);
  void on_key_poses(const key_poses_t& msg);
  // Segments on `channel` (DENSE_SEGMENTS, or its _FULL answer); the new poses on POSE_DENSE.
  void publish(const std::vector<Segment>& segments, const std::string& channel);

  Bus& bus_;
  DensifierConfig config_;
  Densifier densifier_;
  CounterSink counters_;
  std::string child_frame_ = "base";
  int64_t last_dense_published_utime_ = -1;
  int64_t newest_frontend_utime_ = 0;  // [us] utime of DENSE_SEGMENTS: never goes backwards
  int32_t optimisation_ = 0;           // newest backend optimisation seen on KEY_POSES
  double segments_published_ = 0, segment_messages_ = 0, oversize_messages_ = 0;
  double dense_rejected_ = 0;
  double dense_late_ = 0;  // frontend poses flagged FLAG_LATE, left out
  std::unique_ptr<ResendAnswerer> resend_;  // for DENSE_SEGMENTS
};

}  // namespace traverse::densifier
