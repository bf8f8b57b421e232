// Adapts messages to the evaluator: collects the estimate, reference and loop-closure channels
// from a live bus or from an LCM log read event by event, both through the same on_event().
//
// The estimate channel's type is found from each message's fingerprint (type_registry.hpp):
//   pose2d_t          every pose as published;
//   key_poses_t       incremental key poses, the newest pose per id (final_trajectory.hpp);
//   dense_segments_t  the newest revision of each segment (final_trajectory.hpp).
// The first of these seen decides the channel's type; a message of any other type on it is
// counted as a mixed-type message and dropped. The reference is pose2d_t. Loop closures come from
// key_poses_t messages on the key-poses channel (which may also be the estimate channel). The
// frontend's pose2d_t (optional, e.g. to bridge closures to relations) come from its own channel,
// which may be the estimate channel too.
#pragma once

#include <cstddef>
#include <lcm/lcm-cpp.hpp>
#include <set>
#include <string>

#include "bus.hpp"
#include "final_trajectory.hpp"
#include "loop_closures.hpp"
#include "trajectory.hpp"

namespace traverse::evaluator {

enum class EstimateType { kNone, kPose2d, kKeyPoses, kDenseSegments };
// "pose2d_t", "key_poses_t", "dense_segments_t"; "" for kNone.
std::string estimate_type_name(EstimateType type);

class PoseCollector {
 public:
  // `frontend_channel` empty: no frontend poses are collected.
  PoseCollector(std::string estimate_channel, std::string reference_channel,
                std::string key_poses_channel, std::string frontend_channel = "");

  // Live: every message on our channels (one subscription per distinct channel).
  void subscribe(Bus& bus);

  struct LogSummary {
    std::size_t events = 0;           // events read
    std::size_t damaged_records = 0;  // damaged places the reader skipped
  };
  // Offline: every message on our channels of an LCM log. Throws std::runtime_error if the
  // file cannot be opened.
  LogSummary read_log(const std::string& path);

  // One message as received on `channel` (raw bytes).
  void on_event(const std::string& channel, const void* data, int size);

  EstimateType estimate_type() const { return estimate_type_; }
  // The estimate trajectory: every pose2d_t, or the final key poses or dense segments.
  Trajectory estimate() const;
  std::size_t estimate_size() const;  // cheap: poses, key poses or segments so far
  const Trajectory& reference() const { return reference_; }
  const Trajectory& frontend() const { return frontend_; }  // pose2d_t on the frontend channel
  const LoopClosureSet& closures() const { return closures_; }
  const KeyPoseTrajectory& key_poses() const { return key_poses_; }
  const DenseTrajectory& dense() const { return dense_; }

  // Poses with a NaN or infinite coordinate: dropped, they would poison every figure.
  std::size_t non_finite_poses() const { return non_finite_poses_; }
  // Messages on our channels with an unknown fingerprint or that do not decode as their type.
  std::size_t decode_failures() const { return decode_failures_; }
  // Messages on the estimate channel of another type than its first one (or of no estimate
  // type), and on the reference channel that are not pose2d_t: an error, reported.
  std::size_t mixed_type_messages() const { return mixed_type_messages_; }
  // Type names seen on the estimate channel, e.g. {"traverse.pose2d_t", "traverse.imu_t"}.
  const std::set<std::string>& estimate_types_seen() const { return estimate_types_seen_; }

 private:
  void add_estimate(const std::string& type_name, const void* data, int size);
  void add_reference(const std::string& type_name, const void* data, int size);
  void add_closures(const void* data, int size);
  void add_frontend(const void* data, int size);
  // A pose2d_t onto `into`; a message that does not decode or is not finite is left out, and
  // counted when `count`.
  void add_pose(const void* data, int size, Trajectory& into, bool count);

  std::string estimate_channel_;
  std::string reference_channel_;
  std::string key_poses_channel_;
  std::string frontend_channel_;
  EstimateType estimate_type_ = EstimateType::kNone;
  Trajectory pose2d_estimate_;
  KeyPoseTrajectory key_poses_;
  DenseTrajectory dense_;
  Trajectory reference_;
  Trajectory frontend_;
  LoopClosureSet closures_;
  std::size_t non_finite_poses_ = 0;
  std::size_t decode_failures_ = 0;
  std::size_t mixed_type_messages_ = 0;
  std::set<std::string> estimate_types_seen_;
};

}  // namespace traverse::evaluator
