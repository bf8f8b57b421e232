#include "densifier_node.hpp"

#include "channels.hpp"
#include "traverse/dense_segment_t.hpp"

namespace traverse::densifier {

DensifierNode::DensifierNode(Bus& bus, const DensifierConfig& config, CounterSink counters)
    : bus_(bus), config_(config), densifier_(config), counters_(std::move(counters)) {
  bus_.subscribe<pose2d_t>(channels::kPoseFrontend, [this](const pose2d_t& m) { on_frontend(m); });
  bus_.subscribe<key_poses_t>(
      config_.key_pose_channel, [this](const key_poses_t& m) { on_key_poses(m); }, true);
}

void DensifierNode::on_frontend(const pose2d_t& msg) {
  child_frame_ = msg.child_frame;
  std::vector<Segment> closed;
  if (!densifier_.add_dense(msg.utime, Pose2(msg.x, msg.y, msg.theta), &closed)) {
    ++dense_rejected_;
    return;
  }
  publish(closed);
}

void DensifierNode::on_key_poses(const key_poses_t& msg) {
  std::vector<KeyPose> keys;
  for (const key_pose_t& k : msg.poses) keys.push_back({k.id, k.utime, Pose2(k.x, k.y, k.theta)});
  publish(densifier_.update_key_poses(keys));
}

void DensifierNode::publish(const std::vector<Segment>& segments) {
  for (const Segment& s : segments) {
    dense_segment_t seg;
    seg.utime = s.poses.front().utime;
    seg.parent_frame = config_.parent_frame;
    seg.child_frame = child_frame_;
    seg.key_id_first = s.key_id_first;
    seg.key_id_last = s.key_id_last;
    seg.revision = s.revision;
    seg.n_poses = static_cast<int32_t>(s.poses.size());
    for (const StampedPose& p : s.poses) {
      seg.pose_utime.push_back(p.utime);
      seg.x.push_back(p.T_world_base.x());
      seg.y.push_back(p.T_world_base.y());
      seg.theta.push_back(p.T_world_base.theta());
    }
    bus_.publish(channels::kDenseSegment, seg);
    ++segments_published_;
    // The growing trajectory: poses not sent before, in time order (a moved segment is only
    // sent whole above).
    for (const StampedPose& p : s.poses) {
      if (p.utime <= last_dense_published_utime_) continue;
      pose2d_t out{};
      out.utime = p.utime;
      out.parent_frame = config_.parent_frame;
      out.child_frame = child_frame_;
      out.x = p.T_world_base.x();
      out.y = p.T_world_base.y();
      out.theta = p.T_world_base.theta();
      bus_.publish(channels::kPoseDense, out);
      last_dense_published_utime_ = p.utime;
    }
  }
}

void DensifierNode::report_counters() {
  if (!counters_) return;
  counters_("dense_poses", static_cast<double>(densifier_.dense_size()));
  counters_("key_poses", static_cast<double>(densifier_.key_size()));
  counters_("segments_published", segments_published_);
  counters_("segments_moved", static_cast<double>(densifier_.segments_moved()));
  counters_("dense_rejected", dense_rejected_);
}

}  // namespace traverse::densifier
