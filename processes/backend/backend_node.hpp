// Adapts LCM messages to the backend: planar_scan_t (horizontal scanner) and the frontend's
// pose2d_t in; after each optimisation, key_poses_t on KEY_POSES with only the key poses that
// appeared, moved or whose marginal covariance changed (split into parts that each fit one UDP
// datagram), and each new key pose once as pose2d_t (FLAG_KEY_POSE) on POSE_BACKEND.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "backend.hpp"
#include "bus.hpp"
#include "channels.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::backend {

struct BackendNodeConfig {
  std::string scan_channel = channels::kScanHorizontal;
  std::string pose_channel = channels::kPoseFrontend;
  std::string key_poses_channel = channels::kKeyPoses;
  std::string trajectory_channel = channels::kPoseBackend;
  int max_poses_per_message = 400;          // 112 bytes each: 400 keep a part under 64 KB
  double publish_move_m = 0.001;            // a key pose moved farther than this is republished [m]
  double publish_turn_rad = 0.0005;         // ... or turned more than this [rad]
  double publish_covariance_change = 0.01;  // ... or a variance changed by this fraction
  BackendConfig backend;

  template <class V>
  void visit(V& v) {
    v("scan_channel", scan_channel);
    v("pose_channel", pose_channel);
    v("key_poses_channel", key_poses_channel);
    v("trajectory_channel", trajectory_channel);
    v("max_poses_per_message", max_poses_per_message);
    v("publish_move_m", publish_move_m);
    v("publish_turn_rad", publish_turn_rad);
    v("publish_covariance_change", publish_covariance_change);
    v("backend", backend);
  }
};

// An error message when a value is out of range, empty when the config is valid.
std::optional<std::string> validate(const BackendNodeConfig& config);

class BackendNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  // The config must pass validate().
  BackendNode(Bus& bus, const BackendNodeConfig& config, CounterSink counters = {});

  // End of data: closes an open loop-closure episode and publishes the last update.
  void finish();
  void report_counters();
  const Backend& backend() const { return backend_; }
  // Largest encoded key_poses_t sent so far [bytes].
  std::size_t max_message_bytes() const { return max_message_bytes_; }

 private:
  void on_scan(const planar_scan_t& msg);
  void on_pose(const pose2d_t& msg);
  void publish(const BackendUpdate& update);
  bool changed(int index) const;

  Bus& bus_;
  BackendNodeConfig config_;
  Backend backend_;
  CounterSink counters_;
  struct Published {
    Pose2 T_world_base;
    Eigen::Vector3d variances;
  };
  std::vector<Published> published_;
  std::size_t max_message_bytes_ = 0;
  long messages_ = 0;
};

}  // namespace traverse::backend
