#include "pose_collector.hpp"

#include <cmath>

#include "lcm_log.hpp"

namespace traverse::evaluator {

PoseCollector::PoseCollector(std::string estimate_channel, std::string reference_channel)
    : estimate_channel_(std::move(estimate_channel)),
      reference_channel_(std::move(reference_channel)) {}

void PoseCollector::add(const std::string& channel, const pose2d_t& msg) {
  if (!std::isfinite(msg.x) || !std::isfinite(msg.y) || !std::isfinite(msg.theta)) {
    ++non_finite_poses_;
    return;
  }
  const StampedPose p{msg.utime, Pose2(msg.x, msg.y, msg.theta)};
  if (channel == estimate_channel_) estimate_.push_back(p);
  if (channel == reference_channel_) reference_.push_back(p);
}

void PoseCollector::subscribe(Bus& bus) {
  // Out-of-order poses are kept: the evaluator sorts by time anyway.
  bus.subscribe<pose2d_t>(
      estimate_channel_, [this](const pose2d_t& m) { add(estimate_channel_, m); }, true);
  if (reference_channel_ != estimate_channel_) {
    bus.subscribe<pose2d_t>(
        reference_channel_, [this](const pose2d_t& m) { add(reference_channel_, m); }, true);
  }
}

PoseCollector::LogSummary PoseCollector::read_log(const std::string& path) {
  LogReader reader(path);
  LogSummary summary;
  while (auto ev = reader.next()) {
    ++summary.events;
    if (ev->channel != estimate_channel_ && ev->channel != reference_channel_) continue;
    pose2d_t msg;
    const int size = static_cast<int>(ev->data.size());
    if (msg.decode(ev->data.data(), 0, size) != size) {
      ++summary.decode_failures;
      continue;
    }
    add(ev->channel, msg);
  }
  summary.damaged_records = reader.damage().size();
  return summary;
}

}  // namespace traverse::evaluator
