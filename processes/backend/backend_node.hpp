// Adapts LCM messages to the backend: planar_scan_t (horizontal scanner) and the frontend's
// pose2d_t in; after each optimisation, key_poses_t on KEY_POSES with only the key poses that
// appeared, moved or whose marginal covariance changed (split into parts that each fit one UDP
// datagram), and each new key pose once as pose2d_t (FLAG_KEY_POSE) on POSE_BACKEND. Just before
// each KEY_POSES update, the pose-graph edges added since the previous one on POSE_GRAPH_EDGES
// (pose_graph_edges_t, in parts of at most max_poses_per_message edges).
//
// A listener that starts after the backend, or misses a message, holds an incomplete graph: the
// updates are incremental. It asks for the whole graph the graph's one way (common/resend.hpp): a
// resend_request_t on RESEND_REQUEST naming KEY_POSES and/or POSE_GRAPH_EDGES. The node answers
// with every edge on POSE_GRAPH_EDGES_FULL and every key pose on KEY_POSES_FULL (same types and
// parts as the incremental channels, no loop closures listed): separate channels, so that
// listeners that only follow updates (the densifier, which would re-send every segment) never see
// the repeat. At most one answer per channel per resend.pace_s of data time (the newest key
// pose's time, so a replay answers the same way as the live run): a request inside that stretch
// is dropped, the answer having gone to every listener; one that still lacks something asks again
// after the next optimisation.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backend.hpp"
#include "backend_state.hpp"
#include "bus.hpp"
#include "channels.hpp"
#include "resend.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::backend {

struct BackendNodeConfig {
  std::string scan_channel = channels::kScanHorizontal;
  std::string pose_channel = channels::kPoseFrontend;
  std::string odometry_channel = channels::kOdometry;  // odometry_t; empty: none
  std::string key_poses_channel = channels::kKeyPoses;
  std::string trajectory_channel = channels::kPoseBackend;
  std::string edges_channel = channels::kPoseGraphEdges;
  ResendConfig resend;  // resend.pace_s: data time between two answers on a _FULL channel
  int max_poses_per_message = 400;          // 112 bytes each: 400 keep a part under 64 KB
  double publish_move_m = 0.001;            // a key pose moved farther than this is republished [m]
  double publish_turn_rad = 0.0005;         // ... or turned more than this [rad]
  double publish_covariance_change = 0.01;  // ... or a variance changed by this fraction
  // With a state directory (traverse-backend --state-dir): a snapshot of the graph after an
  // optimisation once this much data time passed since the last (backend_state.hpp) [s].
  double state_period_s = 1.0;
  // ... flushed to the disk before it takes effect (fdatasync): survives a power cut, not only a
  // killed process, at tens of milliseconds a snapshot on a busy disk (docs/deployment.md).
  bool state_durable = false;
  BackendConfig backend;

  template <class V>
  void visit(V& v) {
    v("scan_channel", scan_channel);
    v("pose_channel", pose_channel);
    v("odometry_channel", odometry_channel);
    v("key_poses_channel", key_poses_channel);
    v("trajectory_channel", trajectory_channel);
    v("edges_channel", edges_channel);
    v("resend", resend);
    v("max_poses_per_message", max_poses_per_message);
    v("publish_move_m", publish_move_m);
    v("publish_turn_rad", publish_turn_rad);
    v("publish_covariance_change", publish_covariance_change);
    v("state_period_s", state_period_s);
    v("state_durable", state_durable);
    v("backend", backend);
  }
};

// An error message when a value is out of range, empty when the config is valid.
std::optional<std::string> validate(const BackendNodeConfig& config);

// traverse-backend's exit code when its input gave no trajectory (Backend::input_fault()).
inline constexpr int kNoTrajectoryExitCode = 3;

class BackendNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  // The config must pass validate(). With `state_dir`, the backend resumes from the state there
  // if there is one (resumed() says what it found; a damaged state throws std::runtime_error)
  // and keeps its state there (backend_state.hpp).
  BackendNode(Bus& bus, const BackendNodeConfig& config, CounterSink counters = {},
              const std::string& state_dir = "");
  const std::optional<ResumedState>& resumed() const { return resumed_; }

  // End of data: closes an open loop-closure episode and publishes the last update.
  void finish();
  void report_counters();
  const Backend& backend() const { return backend_; }
  // Largest encoded key_poses_t sent so far [bytes].
  std::size_t max_message_bytes() const { return max_message_bytes_; }

 private:
  void on_scan(const planar_scan_t& msg);
  void on_pose(const pose2d_t& msg);
  void on_odometry(const odometry_t& msg);
  // A late listener's request (resend.hpp); true when it was answered.
  bool answer_resend(const ResendRequest& request);
  void publish(const BackendUpdate& update);
  // Edges [first, last) on `channel`.
  void publish_edges(std::size_t first, std::size_t last, int32_t optimisation,
                     const std::string& channel);
  // Key poses `ids` of a graph of the first `n_keys` on `channel`, the update's closures (if any)
  // in part 0.
  void publish_key_poses(const std::vector<int>& ids, std::size_t n_keys,
                         const BackendUpdate& update, const std::string& channel);
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
  long poses_late_ = 0;  // frontend poses flagged FLAG_LATE, left out
  std::size_t edges_published_ = 0;
  BackendUpdate last_update_;  // optimisation counter and time of the newest update
  std::unique_ptr<ResendAnswerer> resend_;
  std::optional<BackendStateStore> state_;
  std::optional<ResumedState> resumed_;
};

}  // namespace traverse::backend
