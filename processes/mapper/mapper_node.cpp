#include "mapper_node.hpp"

#include <algorithm>
#include <filesystem>

#include "channels.hpp"
#include "ply.hpp"
#include "resend.hpp"
#include "scan_message.hpp"
#include "segment_message.hpp"

namespace traverse::mapper {

MapperNode::MapperNode(Bus& bus, const MapperConfig& config, const Eigen::Isometry3d& T_base_laser,
                       CounterSink counters, bool worker_thread, const std::string& state_dir)
    : bus_(bus), config_(config), mapper_(config, T_base_laser), counters_(std::move(counters)) {
  if (!state_dir.empty()) {
    state_ = std::make_unique<MapperStateStore>(state_dir, config_.range_max_m);
    if (auto saved = state_->load()) resume(*saved);
  }
  // After the resume: the preview is of what is new (a viewer keeps what it was sent before; sent
  // again, the old profiles would go back in time).
  if (!config_.preview.channel.empty()) {
    preview_ = std::make_unique<CloudPreview>(config_.preview);
    mapper_.on_first_placement(
        [p = preview_.get()](int64_t t, const Pose2& T, const auto& pts) { p->add(t, T, pts); });
  }
  bus.subscribe<planar_scan_t>(channels::kScanProfile,
                               [this](const planar_scan_t& m) { on_profile(m); });
  if (config_.pose_channel.empty()) {
    bus.subscribe<dense_segments_t>(channels::kDenseSegments,
                                    [this](const dense_segments_t& m) { on_segments(m); });
  } else {
    bus.subscribe<pose2d_t>(config_.pose_channel, [this](const pose2d_t& m) { on_pose(m); });
  }
  if (!config_.annotations_channel.empty()) {
    // Parts of one update share a utime.
    bus.subscribe<annotations_t>(
        config_.annotations_channel, [this](const annotations_t& m) { on_annotations(m); }, true);
    // An annotator already running has annotations this node has not heard.
    bus.subscribe<annotations_t>(
        channels::full_channel(config_.annotations_channel),
        [this](const annotations_t& m) { on_annotations(m); }, true);
    request_resend(bus, "mapper", {config_.annotations_channel});
    ++resend_requests_sent_;
  }
  if (preview_) {
    // Live, a thinning pass runs on a thread of its own: this thread handles the messages.
    resend_store_ = std::make_unique<PreviewResend>(
        config_.preview.cell_m, config_.preview.resend_max_bytes, worker_thread);
    // A requester is being answered until the answer has gone once round the store since it
    // asked.
    const auto answering = [this](const std::string& requester) {
      const auto it = answering_.find(requester);
      return it != answering_.end() && !resend_store_->went_round(it->second);
    };
    resend_ = std::make_unique<ResendAnswerer>(
        bus, std::vector<std::string>{config_.preview.channel},
        [this](const ResendRequest& r) {
          // Paced out by publish_preview(). An answer under way is joined, not restarted
          // (PreviewResend::answer): everyone it goes to gets it in order, once.
          if (resend_store_->resending()) {
            ++resend_requests_joined_;
          } else {
            answering_.clear();
          }
          answering_[r.requester] = resend_store_->answer();
          return true;
        },
        ResendPacing{.min_us = config_.resend.pace_us(),
                     .data_time = [this] { return newest_profile_utime_; },
                     .answering = answering});
  }
  if (worker_thread) worker_ = std::thread([this] { run_worker(); });
}

MapperNode::~MapperNode() { stop_worker(); }

void MapperNode::stop_worker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void MapperNode::resume(SavedInputs& saved) {
  const auto t0 = std::chrono::steady_clock::now();
  // The segments first (the newest revision of each, as on_segments keeps), then the profiles:
  // each is placed once, with the poses it has now, which is the map the moves had made.
  for (SavedSegment& s : saved.segments) {
    if (!take_revision(s.segment.key_id_first, s.revision)) continue;
    next_key_id_ = std::max(next_key_id_, s.segment.key_id_first + 1);
    Work w = std::move(s.segment);
    apply(w);
  }
  for (Profile& p : saved.profiles) {
    Work w = std::move(p);
    apply(w);
  }
  settle();
  resumed_ = Resumed{saved.profiles.size(), saved.segments.size(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()};
}

bool MapperNode::take_revision(int64_t key_id_first, int32_t revision) {
  auto [known, added] = revisions_.try_emplace(key_id_first, revision);
  if (added) return true;
  if (revision <= known->second) return false;
  known->second = revision;
  return true;
}

void MapperNode::on_profile(const planar_scan_t& msg) {
  newest_profile_utime_ = std::max(newest_profile_utime_, msg.utime);
  Profile p{to_planar_scan(msg), {}};
  if (msg.n_intensities8 == msg.n_ranges) {
    p.intensities = msg.intensities8;
  } else if (msg.n_intensities16 == msg.n_ranges) {
    for (int16_t v : msg.intensities16) {
      p.intensities.push_back(static_cast<uint8_t>(static_cast<uint16_t>(v) >> 8));
    }
  }
  if (state_) state_->record(p);
  submit(std::move(p));
  message_done();
}

void MapperNode::on_segments(const dense_segments_t& msg) {
  for (const dense_segment_t& seg : msg.segments) {
    if (!take_revision(seg.key_id_first, seg.revision)) {
      ++segments_stale_;
      continue;
    }
    TrajectorySegment s = segment_of(seg);
    if (state_) state_->record(s, seg.revision);
    submit(std::move(s));
  }
  message_done();
}

void MapperNode::on_pose(const pose2d_t& msg) {
  if (msg.flags & pose2d_t::FLAG_LATE) {  // not the base's pose at its stamp: no part of the path
    ++poses_late_;
    message_done();
    return;
  }
  open_.utimes.push_back(msg.utime);
  open_.T_world_base.emplace_back(msg.x, msg.y, msg.theta);
  if (static_cast<int>(open_.utimes.size()) > config_.poses_per_segment) cut_segment();
  message_done();
}

void MapperNode::cut_segment() {
  if (open_.utimes.size() < 2) return;
  open_.key_id_first = next_key_id_++;
  TrajectorySegment next;
  next.utimes.push_back(open_.utimes.back());  // segments share their end pose
  next.T_world_base.push_back(open_.T_world_base.back());
  if (state_) state_->record(open_, 0);
  submit(std::move(open_));
  open_ = std::move(next);
}

void MapperNode::submit(Work work) {
  if (!worker_.joinable()) {
    apply(work);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    if (queue_.empty()) oldest_queued_at_ = std::chrono::steady_clock::now();
    queue_.push_back(std::move(work));
    ++submitted_;
    max_queued_ = std::max(max_queued_, queue_.size());
  }
  work_cv_.notify_one();
}

void MapperNode::message_done() {
  if (!worker_.joinable()) settle();  // inline: moves once per message, as the worker per batch
}

void MapperNode::apply(Work& work) {
  if (auto* p = std::get_if<Profile>(&work)) {
    latest_utime_ = std::max(latest_utime_, p->utime_last);
    if (!mapper_.add_profile(*p)) ++rejected_;
  } else if (mapper_.set_segment(std::get<TrajectorySegment>(work))) {
    ++segments_applied_;
  } else {
    ++segments_rejected_;
  }
}

void MapperNode::settle() {
  mapper_.apply_moves();
  dropped_ += static_cast<double>(mapper_.drop_stale(latest_utime_));
  Snapshot s;
  s.profiles = static_cast<double>(mapper_.profiles());
  s.pending = static_cast<double>(mapper_.pending());
  s.rejected = rejected_;
  s.dropped = dropped_;
  s.replaced = static_cast<double>(mapper_.profiles_replaced());
  s.points = static_cast<double>(mapper_.points());
  s.filtered = static_cast<double>(mapper_.points_filtered());
  s.voxels = static_cast<double>(mapper_.occupied_voxels());
  s.profile_bytes = static_cast<double>(mapper_.profile_bytes());
  s.segments_applied = segments_applied_;
  s.segments_rejected = segments_rejected_;
  std::lock_guard lock(mutex_);
  snapshot_ = s;
}

void MapperNode::run_worker() {
  std::unique_lock lock(mutex_);
  while (true) {
    work_cv_.wait(lock, [this] { return stop_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping with nothing left
    // Everything queued so far, then the moves once: a loop closure arrives as many segments.
    std::deque<Work> batch;
    batch.swap(queue_);
    const auto oldest = oldest_queued_at_;
    lock.unlock();
    for (Work& w : batch) apply(w);
    settle();
    lock.lock();
    // How far the map trails what has arrived: a loop closure's moved points are in the map
    // (and the cloud) this long after its segments came in.
    lag_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - oldest).count();
    lag_max_s_ = std::max(lag_max_s_, lag_s_);
    done_ += static_cast<int64_t>(batch.size());
    idle_cv_.notify_all();
  }
}

void MapperNode::flush() {
  if (resend_store_) resend_store_->wait();  // a thinning pass under way
  if (!worker_.joinable()) return;
  std::unique_lock lock(mutex_);
  idle_cv_.wait(lock, [this] { return done_ == submitted_; });
}

void MapperNode::finish() {
  if (!config_.pose_channel.empty()) cut_segment();
  flush();
  stop_worker();
  settle();
}

void MapperNode::on_annotations(const annotations_t& msg) {
  for (const key_annotation_t& k : msg.keys) {
    if (colours_.set(k.id, k.utime, k.level, {k.rgb[0], k.rgb[1], k.rgb[2]})) ++level_changes_;
  }
}

bool MapperNode::export_all(std::string* error) {
  flush();  // the worker is idle now and stays so: this thread is the one that would queue more
  std::error_code ec;
  std::filesystem::create_directories(config_.output_dir, ec);
  const std::filesystem::path dir(config_.output_dir);
  // Each file is written aside and renamed over the old one when complete: a mapper killed while
  // it exports leaves the files of the last export whole, never a truncated one.
  const auto replace = [&](const std::string& name) {
    std::filesystem::rename(dir / (name + ".tmp"), dir / name, ec);
    return !ec;
  };
  if (!write_ply((dir / "cloud.ply.tmp").string(), mapper_, &colours_) || !replace("cloud.ply")) {
    if (error) *error = "cannot write " + (dir / "cloud.ply").string();
    return false;
  }
  mapper_.finish_octree_for_export();
  if (!mapper_.octree().writeBinaryConst((dir / "map.bt.tmp").string()) || !replace("map.bt") ||
      !mapper_.octree().write((dir / "map.ot.tmp").string()) || !replace("map.ot")) {
    if (error) *error = "cannot write the OctoMap into " + dir.string();
    return false;
  }
  const auto coloured = coloured_octree(mapper_, colours_, &voxel_colours_);
  if (!coloured->write((dir / "map_colour.ot.tmp").string()) || !replace("map_colour.ot")) {
    if (error) *error = "cannot write " + (dir / "map_colour.ot").string();
    return false;
  }
  return true;
}

namespace {

cloud_preview_t preview_message(const std::vector<PreviewProfile>& profiles, double cell_m) {
  cloud_preview_t m{};
  m.parent_frame = "map";
  m.cell_m = cell_m;
  for (const PreviewProfile& p : profiles) {
    preview_profile_t e{};
    e.utime = p.utime;
    e.n_points = static_cast<int32_t>(p.p_base_mm.size());
    for (const auto& q : p.p_base_mm) {
      e.x_mm.push_back(q[0]);
      e.y_mm.push_back(q[1]);
      e.z_mm.push_back(q[2]);
    }
    m.utime = std::max(m.utime, p.utime);
    m.profiles.push_back(std::move(e));
  }
  m.n_profiles = static_cast<int32_t>(m.profiles.size());
  return m;
}

}  // namespace

void MapperNode::publish_preview() {
  if (!preview_) return;
  resend_store_->poll();  // a pass that has finished
  for (const std::vector<PreviewProfile>& group : preview_->take()) {
    cloud_preview_t m = preview_message(group, config_.preview.cell_m);
    // Profiles go out in the order they are first placed, not in time (one placed with a loop
    // closure's moves comes after newer ones): the channel's time stays where it was.
    preview_utime_ = std::max(preview_utime_, m.utime);
    m.utime = preview_utime_;
    bus_.publish(config_.preview.channel, m);
    ++preview_messages_;
    preview_sent_bytes_ += m.getEncodedSize();
    for (const PreviewProfile& p : group) resend_store_->add(p);
  }
  // A late viewer's answer, at most kResendBytes per kResendWindow: a whole route's preview is
  // tens of MB, and on LCM's multicast every process of the graph receives every message, so at
  // once it would overflow the sockets of the busiest (the frontend's) as well as the viewer's.
  constexpr std::size_t kResendBytes = 64 << 10;
  constexpr auto kResendWindow = std::chrono::milliseconds(100);
  const auto now = std::chrono::steady_clock::now();
  if (now - resend_window_ >= kResendWindow) {
    resend_window_ = now;
    resend_window_bytes_ = 0;
  }
  const std::string full = channels::full_channel(config_.preview.channel);
  const auto per = static_cast<std::size_t>(config_.preview.max_points_per_message);
  while (resend_store_->resending() && resend_window_bytes_ < kResendBytes) {
    cloud_preview_t m = preview_message(resend_store_->next(per), resend_store_->cell_m());
    if (m.n_profiles == 0) break;
    resend_window_bytes_ += static_cast<std::size_t>(m.getEncodedSize());
    bus_.publish(full, m);
    ++resend_messages_;
  }
}

void MapperNode::report_counters() {
  if (!counters_) return;
  Snapshot s;
  double queued = 0, max_queued = 0, lag = 0, lag_max = 0;
  {
    std::lock_guard lock(mutex_);
    s = snapshot_;
    queued = static_cast<double>(queue_.size());
    max_queued = static_cast<double>(max_queued_);
    lag = lag_s_;
    lag_max = lag_max_s_;
  }
  counters_("profiles", s.profiles);
  counters_("poses_late", poses_late_);
  counters_("annotated_key_poses", static_cast<double>(colours_.size()));
  counters_("annotation_level_changes", level_changes_);
  counters_("resend_requests_sent", resend_requests_sent_);
  counters_("voxels_coloured", static_cast<double>(voxel_colours_.voxels));
  counters_("voxels_annotated", static_cast<double>(voxel_colours_.annotated));
  counters_("profiles_pending", s.pending);
  counters_("profiles_rejected", s.rejected);
  counters_("profiles_dropped", s.dropped);
  counters_("profiles_replaced", s.replaced);
  counters_("points", s.points);
  counters_("points_filtered", s.filtered);
  counters_("occupied_voxels", s.voxels);
  counters_("profile_memory_bytes", s.profile_bytes);
  counters_("segments_applied", s.segments_applied);
  counters_("segments_stale", segments_stale_);
  counters_("segments_rejected", s.segments_rejected);
  counters_("work_queued", queued);
  counters_("work_queued_max", max_queued);
  counters_("map_lag_s", lag);
  counters_("map_lag_max_s", lag_max);
  if (state_) {
    const MapperStateCounters& c = state_->counters();
    counters_("state_bytes_appended", c.bytes_appended);
    counters_("state_write_total_s", c.write_total_s);
    counters_("state_compactions", static_cast<double>(c.compactions));
    counters_("state_write_failures", static_cast<double>(c.write_failures));
  }
  if (resumed_) {
    counters_("resumed_profiles", static_cast<double>(resumed_->profiles));
    counters_("resumed_s", resumed_->seconds);
  }
  if (preview_) {
    counters_("preview_points", static_cast<double>(preview_->points()));
    counters_("preview_messages", preview_messages_);
    counters_("preview_sent_bytes", preview_sent_bytes_);
    resend_->report(counters_);
    counters_("resend_requests_joined", resend_requests_joined_);
    counters_("resend_messages", resend_messages_);
    const PreviewResendCounters& r = resend_store_->counters();
    counters_("preview_resend_points", static_cast<double>(resend_store_->points()));
    counters_("preview_resend_profiles", static_cast<double>(resend_store_->profiles()));
    counters_("preview_resend_bytes", static_cast<double>(resend_store_->bytes()));
    counters_("preview_resend_cell_m", resend_store_->cell_m());
    counters_("preview_resend_compactions", static_cast<double>(r.compactions));
    counters_("preview_resend_points_compacted", static_cast<double>(r.points_compacted));
    counters_("preview_resend_compact_max_s", r.compact_max_s);
    counters_("preview_resend_blocked_max_s", r.blocked_max_s);
  }
}

}  // namespace traverse::mapper
