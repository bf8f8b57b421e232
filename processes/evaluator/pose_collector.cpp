#include "pose_collector.hpp"

#include <cmath>

#include "lcm_log.hpp"
#include "traverse/dense_segments_t.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "type_registry.hpp"

namespace traverse::evaluator {
namespace {

const std::string kPose2dName = "traverse.pose2d_t";
const std::string kKeyPosesName = "traverse.key_poses_t";
const std::string kDenseSegmentsName = "traverse.dense_segments_t";

template <class T>
bool decode(const void* data, int size, T& msg) {
  return msg.decode(data, 0, size) == size;
}

bool finite(double x, double y, double theta) {
  return std::isfinite(x) && std::isfinite(y) && std::isfinite(theta);
}

EstimateType type_of(const std::string& name) {
  if (name == kPose2dName) return EstimateType::kPose2d;
  if (name == kKeyPosesName) return EstimateType::kKeyPoses;
  if (name == kDenseSegmentsName) return EstimateType::kDenseSegments;
  return EstimateType::kNone;
}

}  // namespace

std::string estimate_type_name(EstimateType type) {
  switch (type) {
    case EstimateType::kPose2d:
      return "pose2d_t";
    case EstimateType::kKeyPoses:
      return "key_poses_t";
    case EstimateType::kDenseSegments:
      return "dense_segments_t";
    case EstimateType::kNone:
      break;
  }
  return "";
}

PoseCollector::PoseCollector(std::string estimate_channel, std::string reference_channel,
                             std::string key_poses_channel, std::string frontend_channel)
    : estimate_channel_(std::move(estimate_channel)),
      reference_channel_(std::move(reference_channel)),
      key_poses_channel_(std::move(key_poses_channel)),
      frontend_channel_(std::move(frontend_channel)) {}

void PoseCollector::on_event(const std::string& channel, const void* data, int size) {
  const bool estimate = channel == estimate_channel_;
  const bool reference = channel == reference_channel_;
  const bool key_poses = channel == key_poses_channel_;
  const bool frontend = !frontend_channel_.empty() && channel == frontend_channel_;
  if (!estimate && !reference && !key_poses && !frontend) return;
  const TypeInfo* type = find_type(data, static_cast<std::size_t>(size));
  if (type == nullptr) {
    ++decode_failures_;
    return;
  }
  if (estimate) add_estimate(type->name, data, size);
  if (reference) add_reference(type->name, data, size);
  // Another type on the key-poses channel is not ours to judge unless it is the estimate too.
  if (key_poses && type->name == kKeyPosesName) add_closures(data, size);
  if (frontend && type->name == kPose2dName) add_frontend(data, size);
}

void PoseCollector::add_estimate(const std::string& type_name, const void* data, int size) {
  estimate_types_seen_.insert(type_name);
  const EstimateType type = type_of(type_name);
  if (estimate_type_ == EstimateType::kNone) estimate_type_ = type;
  if (type == EstimateType::kNone || type != estimate_type_) {
    ++mixed_type_messages_;
    return;
  }
  switch (type) {
    case EstimateType::kPose2d: {
      pose2d_t m;
      if (!decode(data, size, m)) break;
      if (!finite(m.x, m.y, m.theta)) {
        ++non_finite_poses_;
        return;
      }
      StampedPose p{m.utime, Pose2(m.x, m.y, m.theta)};
      for (int i = 0; i < 9; ++i) p.covariance(i / 3, i % 3) = m.covariance[i];  // row-major
      pose2d_estimate_.push_back(p);
      return;
    }
    case EstimateType::kKeyPoses: {
      key_poses_t m;
      if (!decode(data, size, m)) break;
      for (const key_pose_t& p : m.poses) {
        // A non-finite newest pose still replaces the older one (and is then left out), so that
        // a broken final estimate never hides behind an earlier good one.
        if (!finite(p.x, p.y, p.theta)) ++non_finite_poses_;
        key_poses_.update(p.id, {p.utime, Pose2(p.x, p.y, p.theta)});
      }
      return;
    }
    case EstimateType::kDenseSegments: {
      dense_segments_t m;
      if (!decode(data, size, m)) break;
      for (const dense_segment_t& s : m.segments) {
        DenseSegment segment{s.key_id_first, s.key_id_last, s.revision, {}};
        segment.poses.reserve(static_cast<std::size_t>(s.n_poses));
        for (int i = 0; i < s.n_poses; ++i) {
          if (!finite(s.x[i], s.y[i], s.theta[i])) ++non_finite_poses_;
          segment.poses.push_back({s.pose_utime[i], Pose2(s.x[i], s.y[i], s.theta[i])});
        }
        dense_.update(std::move(segment));
      }
      return;
    }
    case EstimateType::kNone:
      return;
  }
  ++decode_failures_;
}

void PoseCollector::add_reference(const std::string& type_name, const void* data, int size) {
  if (type_name != kPose2dName) {
    ++mixed_type_messages_;
    return;
  }
  add_pose(data, size, reference_, true);
}

void PoseCollector::add_closures(const void* data, int size) {
  key_poses_t m;
  if (!decode(data, size, m)) {
    // Counted once: when this channel is also the estimate, add_estimate counted it already.
    if (key_poses_channel_ != estimate_channel_) ++decode_failures_;
    return;
  }
  for (const loop_closure_t& l : m.closures) {
    LoopClosure c;
    c.from_id = l.from_id;
    c.to_id = l.to_id;
    c.from_utime = l.from_utime;
    c.to_utime = l.utime;
    c.T_from_to = Pose2(l.x, l.y, l.theta);
    for (int i = 0; i < 9; ++i) c.covariance(i / 3, i % 3) = l.covariance[i];  // row-major
    closures_.add(c);
  }
}

void PoseCollector::add_frontend(const void* data, int size) {
  // Counted where the estimate or reference read the same message already.
  const bool counted =
      frontend_channel_ == estimate_channel_ || frontend_channel_ == reference_channel_;
  add_pose(data, size, frontend_, !counted);
}

void PoseCollector::add_pose(const void* data, int size, Trajectory& into, bool count) {
  pose2d_t m{};
  if (!decode(data, size, m)) {
    if (count) ++decode_failures_;
    return;
  }
  if (!finite(m.x, m.y, m.theta)) {
    if (count) ++non_finite_poses_;
    return;
  }
  into.push_back({m.utime, Pose2(m.x, m.y, m.theta)});
}

Trajectory PoseCollector::estimate() const {
  switch (estimate_type_) {
    case EstimateType::kKeyPoses:
      return key_poses_.trajectory();
    case EstimateType::kDenseSegments:
      return dense_.trajectory();
    case EstimateType::kPose2d:
    case EstimateType::kNone:
      break;
  }
  return pose2d_estimate_;
}

std::size_t PoseCollector::estimate_size() const {
  switch (estimate_type_) {
    case EstimateType::kKeyPoses:
      return key_poses_.size();
    case EstimateType::kDenseSegments:
      return dense_.size();
    case EstimateType::kPose2d:
    case EstimateType::kNone:
      break;
  }
  return pose2d_estimate_.size();
}

void PoseCollector::subscribe(Bus& bus) {
  // Raw subscriptions: the type is decided per message from its fingerprint, exactly as offline.
  std::set<std::string> channels = {estimate_channel_, reference_channel_, key_poses_channel_};
  if (!frontend_channel_.empty()) channels.insert(frontend_channel_);
  for (const std::string& channel : channels) {
    bus.subscribe_raw(channel, [this](const std::string& ch, const uint8_t* data, int size,
                                      int64_t) { on_event(ch, data, size); });
  }
}

PoseCollector::LogSummary PoseCollector::read_log(const std::string& path) {
  LogReader reader(path);
  LogSummary summary;
  while (auto ev = reader.next()) {
    ++summary.events;
    on_event(ev->channel, ev->data.data(), static_cast<int>(ev->data.size()));
  }
  summary.damaged_records = reader.damage().size();
  return summary;
}

}  // namespace traverse::evaluator
