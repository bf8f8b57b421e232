#include "densifier_node.hpp"

#include <algorithm>

#include "channels.hpp"

namespace traverse::densifier {

namespace {

dense_segment_t to_message(const Segment& s) {
  dense_segment_t seg;
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
  return seg;
}

}  // namespace

std::vector<dense_segments_t> pack_segments(const std::vector<Segment>& segments,
                                            const std::string& parent_frame,
                                            const std::string& child_frame, int32_t optimisation,
                                            int max_bytes) {
  dense_segments_t empty{};
  empty.parent_frame = parent_frame;
  empty.child_frame = child_frame;
  empty.optimisation = optimisation;
  // Encoded size without segments (hash, fixed fields, both strings); each element adds its own.
  const int header_bytes = empty.getEncodedSize();
  std::vector<dense_segments_t> out;
  int bytes = 0;
  for (const Segment& s : segments) {
    dense_segment_t seg = to_message(s);
    const int seg_bytes = seg._getEncodedSizeNoHash();
    if (out.empty() || (out.back().n_segments > 0 && bytes + seg_bytes > max_bytes)) {
      out.push_back(empty);
      bytes = header_bytes;
    }
    out.back().segments.push_back(std::move(seg));
    ++out.back().n_segments;
    bytes += seg_bytes;
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].part = static_cast<int32_t>(i);
    out[i].parts = static_cast<int32_t>(out.size());
  }
  return out;
}

DensifierNode::DensifierNode(Bus& bus, const DensifierConfig& config, CounterSink counters)
    : bus_(bus), config_(config), densifier_(config), counters_(std::move(counters)) {
  bus_.subscribe<pose2d_t>(channels::kPoseFrontend, [this](const pose2d_t& m) { on_frontend(m); });
  bus_.subscribe<key_poses_t>(
      config_.key_pose_channel, [this](const key_poses_t& m) { on_key_poses(m); }, true);
  // Its listener (the viewer) asks once, at start: each requester is answered, at most once per
  // resend.pace_s of frontend time.
  resend_ = std::make_unique<ResendAnswerer>(
      bus_, std::vector<std::string>{channels::kDenseSegments},
      [this](const ResendRequest&) {
        publish(densifier_.sent_segments(), channels::full_channel(channels::kDenseSegments));
        return true;
      },
      ResendPacing{.min_us = config_.resend.pace_us(),
                   .data_time = [this] { return newest_frontend_utime_; }});
}

void DensifierNode::on_frontend(const pose2d_t& msg) {
  child_frame_ = msg.child_frame;
  if (msg.flags & pose2d_t::FLAG_LATE) {  // not the base's pose at its stamp: no part of the path
    ++dense_late_;
    return;
  }
  std::vector<Segment> closed;
  if (!densifier_.add_dense(msg.utime, Pose2(msg.x, msg.y, msg.theta), &closed)) {
    ++dense_rejected_;
    return;
  }
  newest_frontend_utime_ = std::max(newest_frontend_utime_, msg.utime);
  publish(closed, channels::kDenseSegments);
}

void DensifierNode::on_key_poses(const key_poses_t& msg) {
  optimisation_ = std::max(optimisation_, msg.optimisation);
  std::vector<KeyPose> keys;
  for (const key_pose_t& k : msg.poses) keys.push_back({k.id, k.utime, Pose2(k.x, k.y, k.theta)});
  publish(densifier_.update_key_poses(keys), channels::kDenseSegments);
}

void DensifierNode::publish(const std::vector<Segment>& segments, const std::string& channel) {
  if (segments.empty()) return;
  for (dense_segments_t& msg : pack_segments(segments, config_.parent_frame, child_frame_,
                                             optimisation_, config_.max_message_bytes)) {
    msg.utime = newest_frontend_utime_;
    if (msg.getEncodedSize() > config_.max_message_bytes) ++oversize_messages_;
    bus_.publish(channel, msg);
    ++segment_messages_;
    segments_published_ += msg.n_segments;
  }
  // The growing trajectory: poses not sent before, in time order (a moved segment is only sent
  // whole above).
  for (const Segment& s : segments) {
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

void DensifierNode::finish() { publish(densifier_.settle(), channels::kDenseSegments); }

void DensifierNode::report_counters() {
  if (!counters_) return;
  counters_("dense_poses", static_cast<double>(densifier_.dense_size()));
  counters_("key_poses", static_cast<double>(densifier_.key_size()));
  counters_("segments_published", segments_published_);
  counters_("segment_messages", segment_messages_);
  counters_("oversize_messages", oversize_messages_);
  counters_("segments_moved", static_cast<double>(densifier_.segments_moved()));
  counters_("spikes_replaced", static_cast<double>(densifier_.spikes_replaced()));
  counters_("dense_rejected", dense_rejected_);
  counters_("dense_late", dense_late_);
  resend_->report(counters_);
}

}  // namespace traverse::densifier
