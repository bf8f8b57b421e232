#include "mapper_node.hpp"

#include <filesystem>

#include "channels.hpp"
#include "ply.hpp"

namespace traverse::mapper {

MapperNode::MapperNode(Bus& bus, const MapperConfig& config, const Eigen::Isometry3d& T_base_laser,
                       CounterSink counters)
    : config_(config), mapper_(config, T_base_laser), counters_(std::move(counters)) {
  bus.subscribe<planar_scan_t>(channels::kScanProfile,
                               [this](const planar_scan_t& m) { on_profile(m); });
  if (config_.pose_channel.empty()) {
    bus.subscribe<dense_segment_t>(
        channels::kDenseSegment, [this](const dense_segment_t& m) { on_segment(m); }, true);
  } else {
    bus.subscribe<pose2d_t>(config_.pose_channel, [this](const pose2d_t& m) { on_pose(m); });
  }
}

void MapperNode::on_profile(const planar_scan_t& msg) {
  Profile p;
  p.utime_first = msg.utime_first;
  p.utime_last = msg.utime_last;
  p.angle_first = msg.angle_first;
  p.angle_step = msg.angle_step;
  p.ranges = msg.ranges;
  if (msg.n_intensities8 == msg.n_ranges) {
    p.intensities = msg.intensities8;
  } else if (msg.n_intensities16 == msg.n_ranges) {
    for (int16_t v : msg.intensities16) {
      p.intensities.push_back(static_cast<uint8_t>(static_cast<uint16_t>(v) >> 8));
    }
  }
  latest_utime_ = std::max(latest_utime_, msg.utime_last);
  if (!mapper_.add_profile(p)) ++rejected_;
}

void MapperNode::on_segment(const dense_segment_t& msg) {
  TrajectorySegment s;
  s.key_id_first = msg.key_id_first;
  s.utimes = msg.pose_utime;
  for (int i = 0; i < msg.n_poses; ++i)
    s.T_world_base.emplace_back(msg.x[i], msg.y[i], msg.theta[i]);
  if (!mapper_.set_segment(s)) ++rejected_;
}

void MapperNode::on_pose(const pose2d_t& msg) {
  open_.utimes.push_back(msg.utime);
  open_.T_world_base.emplace_back(msg.x, msg.y, msg.theta);
  if (static_cast<int>(open_.utimes.size()) > config_.poses_per_segment) cut_segment();
}

void MapperNode::cut_segment() {
  if (open_.utimes.size() < 2) return;
  open_.key_id_first = next_key_id_++;
  TrajectorySegment next;
  next.utimes.push_back(open_.utimes.back());  // segments share their end pose
  next.T_world_base.push_back(open_.T_world_base.back());
  if (!mapper_.set_segment(open_)) ++rejected_;
  open_ = std::move(next);
}

void MapperNode::tick() {
  mapper_.apply_moves();
  dropped_ += static_cast<double>(mapper_.drop_stale(latest_utime_));
}

void MapperNode::finish() {
  if (!config_.pose_channel.empty()) cut_segment();
  mapper_.apply_moves();
}

bool MapperNode::export_all(std::string* error) {
  std::error_code ec;
  std::filesystem::create_directories(config_.output_dir, ec);
  const std::filesystem::path dir(config_.output_dir);
  if (!write_ply((dir / "cloud.ply").string(), mapper_)) {
    if (error) *error = "cannot write " + (dir / "cloud.ply").string();
    return false;
  }
  mapper_.finish_octree_for_export();
  if (!mapper_.octree().writeBinaryConst((dir / "map.bt").string()) ||
      !mapper_.octree().write((dir / "map.ot").string())) {
    if (error) *error = "cannot write the OctoMap into " + dir.string();
    return false;
  }
  return true;
}

void MapperNode::report_counters() {
  if (!counters_) return;
  counters_("profiles", static_cast<double>(mapper_.profiles()));
  counters_("profiles_pending", static_cast<double>(mapper_.pending()));
  counters_("profiles_rejected", rejected_);
  counters_("profiles_dropped", dropped_);
  counters_("profiles_replaced", static_cast<double>(mapper_.profiles_replaced()));
  counters_("points", static_cast<double>(mapper_.points()));
  counters_("points_filtered", static_cast<double>(mapper_.points_filtered()));
  counters_("occupied_voxels", static_cast<double>(mapper_.occupied_voxels()));
  counters_("profile_memory_bytes", static_cast<double>(mapper_.profile_bytes()));
}

}  // namespace traverse::mapper
