#include "frontend_node.hpp"

#include "scan_message.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::frontend {

FrontendNode::FrontendNode(Bus& bus, const FrontendConfig& config, CounterSink counters)
    : bus_(bus), config_(config), frontend_(make_frontend(config)), counters_(std::move(counters)) {
  bus_.subscribe<planar_scan_t>(config_.scan_channel,
                                [this](const planar_scan_t& m) { on_scan(m); });
  bus_.subscribe<imu_t>(config_.imu_channel, [this](const imu_t& m) { on_imu(m); });
  bus_.subscribe<odometry_t>(config_.odometry_channel,
                             [this](const odometry_t& m) { on_odometry(m); });
}

void FrontendNode::on_scan(const planar_scan_t& msg) {
  pending_.push_back(to_planar_scan(msg));
  flush();
}

void FrontendNode::on_imu(const imu_t& msg) {
  const Eigen::Vector3d angular_velocity(msg.angular_velocity[0], msg.angular_velocity[1],
                                         msg.angular_velocity[2]);
  if (frontend_->add_imu(msg.utime, angular_velocity)) last_imu_utime_ = msg.utime;
  flush();
}

void FrontendNode::on_odometry(const odometry_t& msg) {
  OdometrySample o;
  o.utime = msg.utime;
  o.T_odom_base = Pose2(msg.x, msg.y, msg.theta);
  for (int i = 0; i < 9; ++i) o.pose_covariance(i / 3, i % 3) = msg.pose_covariance[i];
  if (frontend_->add_odometry(o)) last_odometry_utime_ = msg.utime;
  flush();
}

void FrontendNode::flush(bool all) {
  const auto covered = [](const std::optional<int64_t>& last, int64_t utime) {
    return !last || *last >= utime;
  };
  while (!pending_.empty()) {
    const Scan& scan = pending_.front();
    const bool ready = all ||
                       (covered(last_imu_utime_, scan.utime_last) &&
                        covered(last_odometry_utime_, scan.utime_last)) ||
                       pending_.back().utime_last - scan.utime_last >= config_.deskew.imu_wait_us;
    if (!ready) break;
    const FrontendResult result = frontend_->process(scan);
    pending_.pop_front();
    if (result.has_pose()) publish(result);
  }
  if (!all) return;
  // The end of the stream: the scan the lag still holds (sparse_lag) gets its pose.
  if (const auto result = frontend_->finish()) publish(*result);
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
  frontend_->report(counters_);
  counters_("scans_waiting_for_imu", static_cast<double>(pending_.size()));
  counters_("map_bytes", static_cast<double>(frontend_->map_bytes()));
}

}  // namespace traverse::frontend
