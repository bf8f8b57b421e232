// Starting a frontend where another left off, so that the trajectory does not jump: the frontend
// swapped in while the graph runs (a FRONTEND_CONTROL message, frontend_node.hpp) and a mapping
// session resumed from its saved state.
//
// The node keeps the last window_s of what its frontend took (scans, IMU and odometry samples) and
// the pose it published for each scan. To start another frontend:
//   1. it is made (make_frontend) with its first pose at the published pose of the oldest scan
//      held, and re-tracks the held scans in order, the IMU and odometry samples interleaved as
//      they came: its map is built from the recent scans, by its own matching;
//   2. its pose at the newest held scan is aligned with the pose published for it: from then on
//      its poses are published as T_published = C * T_own, C = T_published_last * T_own_last^-1
//      (its covariance turned by C's rotation). C stays near the identity (the two frontends'
//      disagreement over the window: millimetres on the simulated office); the first pose it
//      publishes continues from the last one published, whatever kind published it.
// The same held window, written to a file when a session stops, is what a resumed session starts
// from (serialise/restore), and the saved scans are what its first scans are checked against
// (fit).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "frontend.hpp"
#include "handover_config.hpp"
#include "icp/point_map.hpp"

namespace traverse::frontend {

class Handover {
 public:
  explicit Handover(const HandoverConfig& config) : config_(config) {}

  void add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu);
  void add_odometry(const OdometrySample& odometry);
  // A scan the running frontend took, then the pose published for it (if one is).
  void add_scan(const Scan& scan);
  void add_published(int64_t utime, const Pose2& T_map_base);

  struct Started {
    std::unique_ptr<Frontend> frontend;
    Pose2 C;                 // T_published = C * T_own
    int scans = 0;           // scans re-tracked
    double misfit_m = 0;     // [m] |translation of C relative to the last pose| before alignment
    double misfit_rad = 0;   // [rad]
    int64_t last_utime = 0;  // [us] the newest scan re-tracked
  };
  // A frontend of `config` (its kind) started as the header says; nullopt when no held scan has a
  // published pose.
  std::optional<Started> start(const FrontendConfig& config) const;

  // The share of `scan`'s valid points, placed at T_map_base, within fit_distance_m of a point of
  // the held scans placed at their published poses (0 when none are held).
  double fit(const Scan& scan, const Pose2& T_map_base, const FrontendConfig& config) const;

  bool empty() const { return scans_.empty(); }
  std::size_t scans() const { return scans_.size(); }
  // The newest published pose held (the session's last pose).
  std::optional<std::pair<int64_t, Pose2>> last_published() const;

  std::string serialise() const;
  // False (and nothing changed) when `bytes` is not a serialised window.
  bool restore(const std::string& bytes);

 private:
  struct Held {
    Scan scan;
    std::optional<Pose2> T_published;
  };
  struct Sample {
    int64_t utime = 0;
    bool imu = false;
    Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // imu
    OdometrySample odometry;                                     // !imu
  };
  void trim();

  HandoverConfig config_;
  std::deque<Held> scans_;
  // The held scans' points at their published poses, made by the first fit() (a resumed
  // session's saved window does not change while its first scans are checked).
  mutable std::optional<PointMap> fit_map_;
  std::deque<Sample> samples_;  // in the order they came
};

}  // namespace traverse::frontend
