#include "viewer_node.hpp"

#include <chrono>

#include "channels.hpp"
#include "guidance.hpp"
#include "message_checks.hpp"
#include "resend.hpp"
#include "segment_message.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse::viewer {

ViewerNode::ViewerNode(Bus& bus, const ViewerConfig& config, WebServer* server,
                       CounterSink counters)
    : bus_(bus),
      config_(config),
      server_(server),
      counters_(std::move(counters)),
      scene_(SceneConfig{config.trajectory_step_m, config.pose_history_s, config.max_points}) {
  // Several messages of one update share a utime (parts), so order is not checked on these.
  bus_.subscribe<cloud_preview_t>(
      config_.preview_channel, [this](const cloud_preview_t& m) { on_preview(m); }, true);
  bus_.subscribe<dense_segments_t>(
      config_.segments_channel, [this](const dense_segments_t& m) { on_segments(m); }, true);
  bus_.subscribe<annotations_t>(
      config_.annotations_channel, [this](const annotations_t& m) { on_annotations(m); }, true);
  // What the graph published before this viewer started: asked for once, answered on the _FULL
  // channels (resend.hpp) and read like the live ones.
  bus_.subscribe<cloud_preview_t>(
      channels::full_channel(config_.preview_channel),
      [this](const cloud_preview_t& m) { on_preview(m); }, true);
  bus_.subscribe<dense_segments_t>(
      channels::full_channel(config_.segments_channel),
      [this](const dense_segments_t& m) { on_segments(m); }, true);
  bus_.subscribe<annotations_t>(
      channels::full_channel(config_.annotations_channel),
      [this](const annotations_t& m) { on_annotations(m); }, true);
  if (config_.ask_for_state) {
    request_resend(
        bus_, "viewer",
        {config_.preview_channel, config_.segments_channel, config_.annotations_channel});
    ++resend_requests_sent_;
  }
  bus_.subscribe<pose2d_t>(config_.pose_channel, [this](const pose2d_t& m) { on_pose(m); });
  // Every process's status: one subscription for all, decoded here with the bus's checks (a typed
  // subscription would count the processes' interleaved sequence numbers as losses).
  status_subscription_ = bus_.subscribe_raw(
      config_.status_prefix + ".*", [this](const std::string& channel, const uint8_t* data,
                                           int size, int64_t) { on_status(channel, data, size); });
}

ViewerNode::~ViewerNode() {
  if (status_subscription_) bus_.unsubscribe(status_subscription_);
}

void ViewerNode::on_preview(const cloud_preview_t& msg) {
  for (const preview_profile_t& p : msg.profiles) {
    std::vector<std::array<int16_t, 3>> pts(static_cast<std::size_t>(p.n_points));
    for (int i = 0; i < p.n_points; ++i) pts[i] = {p.x_mm[i], p.y_mm[i], p.z_mm[i]};
    scene_.add_profile(p.utime, std::move(pts));
  }
}

void ViewerNode::on_segments(const dense_segments_t& msg) {
  for (const dense_segment_t& s : msg.segments)
    scene_.set_segment(mapper::segment_of(s), s.revision);
}

void ViewerNode::on_annotations(const annotations_t& msg) {
  Legend legend;
  legend.standard = msg.standard;
  legend.coloured_by = msg.coloured_by;
  legend.bound_method = msg.bound_method;
  legend.confidence = msg.confidence;
  legend.best_level = msg.best_level;
  legend.worst_level = msg.worst_level;
  for (const accuracy_level_t& l : msg.levels) {
    legend.levels.push_back(
        {l.name, l.min_m, l.max_m, {l.rgb[0], l.rgb[1], l.rgb[2]}, l.accepted != 0});
  }
  std::vector<KeyAnnotation> keys;
  for (const key_annotation_t& k : msg.keys) {
    keys.push_back({k.id, k.utime, k.x, k.y, k.bound_m, k.local_bound_m, k.level});
  }
  scene_.set_annotations(legend, keys);
}

void ViewerNode::on_pose(const pose2d_t& msg) {
  scene_.set_frontend_pose(msg.utime, Pose2(msg.x, msg.y, msg.theta));
}

void ViewerNode::on_status(const std::string&, const uint8_t* data, int size) {
  process_status_t st;
  if (decode_checked(data, size, {}, st).verdict != MessageVerdict::kGood) {
    ++statuses_rejected_;
    return;
  }
  if (!board_.update(report_of(st))) {
    ++statuses_stale_;  // not newer than the one held for that process
    return;
  }
  ++statuses_;
  status_changed_ = true;
}

void ViewerNode::update(int64_t now_utime) {
  if (now_utime - last_update_utime_ < static_cast<int64_t>(config_.update_period_s * 1e6)) return;
  last_update_utime_ = now_utime;
  const auto t0 = std::chrono::steady_clock::now();
  const Changes changes = scene_.take_changes();
  if (!server_ || server_->counters().clients == 0) return;  // a browser that comes gets a snapshot
  std::vector<Frame> frames = encode_changes(scene_, changes);
  board_.age(now_utime);
  const Frame status = encode_status(board_, now_utime);
  if (status_changed_) frames.push_back(status);
  status_changed_ = false;
  std::optional<Frame> guidance;
  const auto now = scene_.current_pose();
  if (scene_.legend() && now) {
    guidance = encode_guidance(
        guide(scene_.annotations(), *scene_.legend(), *now, config_.loop_min_age_s));
    if (*guidance->data != last_guidance_) frames.push_back(*guidance);  // only when it changed
    last_guidance_ = *guidance->data;
  }
  server_->broadcast(frames);
  if (server_->snapshot_wanted()) {
    std::vector<Frame> all = encode_snapshot(scene_);
    all.push_back(status);
    all.push_back(encode_view(config_.voxel_m, config_.redraw_period_s));
    if (guidance) all.push_back(*guidance);
    server_->send_snapshot(all);
  }
  ++updates_sent_;
  update_s_max_ = std::max(
      update_s_max_, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

void ViewerNode::report_counters() {
  if (!counters_) return;
  const SceneCounters& c = scene_.counters();
  counters_("points", static_cast<double>(scene_.points()));
  counters_("profiles", static_cast<double>(scene_.profiles().size()));
  counters_("key_poses_annotated", static_cast<double>(scene_.annotations().size()));
  counters_("trajectory_segments", static_cast<double>(scene_.polylines().size()));
  counters_(config_.preview_channel + "/rejected", static_cast<double>(c.profiles_rejected));
  counters_("profiles_repeated", static_cast<double>(c.profiles_repeated));
  counters_("points_dropped", static_cast<double>(c.points_dropped));
  counters_(config_.segments_channel + "/rejected", static_cast<double>(c.segments_rejected));
  counters_("segments_stale", static_cast<double>(c.segments_stale));
  counters_(config_.annotations_channel + "/rejected", static_cast<double>(c.annotations_rejected));
  counters_("statuses", statuses_);
  counters_("statuses_stale", statuses_stale_);
  counters_("resend_requests_sent", resend_requests_sent_);
  counters_(config_.status_prefix + "*/rejected", statuses_rejected_);
  counters_("updates_sent", updates_sent_);
  counters_("update_max_s", update_s_max_);
  if (!server_) return;
  const WebServer::Counters s = server_->counters();
  counters_("http_port", server_->port());
  counters_("browsers", static_cast<double>(s.clients));
  counters_("browser_connections", static_cast<double>(s.connections));
  counters_("http_requests", static_cast<double>(s.http_requests));
  counters_("http_not_found", static_cast<double>(s.http_not_found));
  counters_("frames_sent", static_cast<double>(s.frames_sent));
  counters_("sent_bytes", static_cast<double>(s.bytes_sent));
  counters_("frames_dropped", static_cast<double>(s.frames_dropped));
  counters_("dropped_bytes", static_cast<double>(s.bytes_dropped));
  counters_("snapshots", static_cast<double>(s.snapshots));
  counters_("browser_queue_max_bytes", static_cast<double>(s.queued_bytes_max));
}

}  // namespace traverse::viewer
