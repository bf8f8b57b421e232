#include "frontend_node.hpp"

#include "scan_message.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::frontend {

FrontendNode::FrontendNode(Bus& bus, const FrontendConfig& config, CounterSink counters)
    : bus_(bus), config_(config), frontend_(config), counters_(std::move(counters)) {
  bus_.subscribe<planar_scan_t>(config_.scan_channel,
                                [this](const planar_scan_t& m) { on_scan(m); });
  bus_.subscribe<imu_t>(config_.imu_channel, [this](const imu_t& m) { on_imu(m); });
}

void FrontendNode::on_scan(const planar_scan_t& msg) {
  pending_.push_back(to_planar_scan(msg));
  flush();
}

void FrontendNode::on_imu(const imu_t& msg) {
  frontend_.add_imu(msg.utime, Eigen::Vector3d(msg.angular_velocity[0], msg.angular_velocity[1],
                                               msg.angular_velocity[2]));
  flush();
}

void FrontendNode::flush(bool all) {
  const auto last_imu = frontend_.last_imu_utime();
  while (!pending_.empty()) {
    const Scan& scan = pending_.front();
    const bool ready = all || !last_imu || *last_imu >= scan.utime_last ||
                       pending_.back().utime_last - scan.utime_last >= config_.deskew.imu_wait_us;
    if (!ready) break;
    const FrontendResult result = frontend_.process(scan);
    pending_.pop_front();
    if (result.has_pose()) publish(result);
  }
  if (!all) return;
  // The end of the stream: the scan the lag still holds (sparse_lag) gets its pose.
  if (const auto result = frontend_.finish()) publish(*result);
}

void FrontendNode::publish(const FrontendResult& result) {
  pose2d_t msg{};
  msg.utime = result.utime;
  msg.parent_frame = "map";
  msg.child_frame = "base";
  msg.x = result.T_map_base.x();
  msg.y = result.T_map_base.y();
  msg.theta = result.T_map_base.theta();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) msg.covariance[3 * r + c] = result.covariance(r, c);
  }
  msg.flags = result.status == ScanStatus::kPredicted ? pose2d_t::FLAG_PREDICTED : 0;
  bus_.publish(config_.pose_channel, msg);
}

void FrontendNode::report_counters() {
  if (!counters_) return;
  const FrontendCounters& c = frontend_.counters();
  counters_("scans_received", static_cast<double>(c.scans_received));
  counters_("scans_matched", static_cast<double>(c.scans_matched));
  counters_("scans_predicted", static_cast<double>(c.scans_predicted));
  counters_("scans_unverified", static_cast<double>(c.scans_unverified));
  counters_("scans_searched", static_cast<double>(c.scans_searched));
  counters_("scans_dropped_time", static_cast<double>(c.scans_dropped_time));
  counters_("scans_waiting_for_imu", static_cast<double>(pending_.size()));
  counters_("readings_invalid", static_cast<double>(c.readings_invalid));
  counters_("map_updates", static_cast<double>(c.map_updates));
  counters_("map_tiles_evicted", static_cast<double>(c.map_tiles_evicted));
  counters_("map_bytes", static_cast<double>(frontend_.map_memory_bytes()));
  counters_("imu_samples", static_cast<double>(c.imu_samples));
  counters_("imu_dropped", static_cast<double>(c.imu_dropped_time));
  counters_("steps_disputed", static_cast<double>(c.steps_disputed));
  counters_("steps_outvoted", static_cast<double>(c.steps_outvoted));
  counters_("scans_revised", static_cast<double>(c.scans_revised));
}

}  // namespace traverse::frontend
