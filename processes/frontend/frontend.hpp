// What traverse-frontend runs: a Frontend takes the horizontal scanner's sweeps (and IMU and wheel
// odometry, where it uses them) and gives one pose of the base in its map frame per sweep, with
// its covariance. The node (frontend_node.hpp) owns one, made by make_frontend() from the config,
// and knows nothing else about it; docs/frontends.md shows how another kind plugs in.
//
// The frontend shipped is the Hector scan-to-map matcher (hector/hector_frontend.hpp), a
// two-phase frontend (two_phase.hpp: measure a scan against the map, then integrate it). On a
// sparse log (scans far apart, no odometry) it runs inside the wrappers of sparse/: one scan
// behind (sparse/lag.hpp) and as an ensemble on offset grids that votes on each step
// (sparse/ensemble.hpp). Which of them run is the config's (MatcherConfig::sparse_lag and
// sparse_ensemble_members).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "frontend_config.hpp"
#include "planar_scan.hpp"
#include "se2.hpp"

namespace traverse::frontend {

using Scan = PlanarScan;

// One wheel-odometry message: what the motion prior uses of a traverse::odometry_t.
struct OdometrySample {
  int64_t utime = 0;  // [us] time of the encoder reading
  Pose2 T_odom_base;  // in the odometry's drifting frame: only differences mean anything
  Eigen::Matrix3d pose_covariance = Eigen::Matrix3d::Zero();  // (x [m], y [m], theta [rad]), odom
};

enum class ScanStatus {
  kMatched,    // pose measured by matching (the first scan: its pose is the config's initial_pose)
  kPredicted,  // pose predicted from motion: too few valid points, or an unverified match
  kDropped,    // time does not advance or is inconsistent: no pose
  kHeld,       // no pose yet: it comes with a later scan's result or from finish() (sparse/lag.hpp)
};

// What a frontend may tell about how it got a pose, beyond the pose (for tests, benchmarks and
// traces; the node publishes none of it).
struct FrontendDiagnostics {
  Pose2 T_map_base_predicted;  // the motion prediction the match started from
  bool imu_used = false;
  bool map_updated = false;
  int valid_points = 0;
  int matched_points = 0;
  int iterations = 0;
  double residual_rms = 0.0;  // [unitless] RMS of 1 - M at the result (Hector)
  bool searched = false;      // the matcher needed a correlative search
  // Smallest over largest eigenvalue of the scan's information (Hector: hector/degeneracy.hpp),
  // 0 to 1, and how many directions were held at the prediction.
  double degeneracy_ratio = 1.0;
  int degenerate_directions = 0;
  // Sparse-scan ensemble: members whose step agrees with the published one, of how many voted.
  int ensemble_agreeing = 0, ensemble_voting = 0;
};

struct FrontendResult {
  ScanStatus status = ScanStatus::kDropped;
  bool has_pose() const {
    return status == ScanStatus::kMatched || status == ScanStatus::kPredicted;
  }
  int64_t utime = 0;  // [us] time the pose is valid at: the scan's last point
  Pose2 T_map_base;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // (x [m], y [m], theta [rad]), map frame
  // The scan came far from the previous one (a log subsampled by travel, or a pause in a
  // scanner's stream): the wrappers of sparse/ act on such scans.
  bool sparse = false;
  // The scan was taken before its stamp and stamped late: T_map_base is where its points belong,
  // not the base's pose at utime (pose2d_t::FLAG_LATE).
  bool late = false;
  std::optional<FrontendDiagnostics> diagnostics;
};

// Status counters (name with unit: _s, _m, _bytes, or a count) as a frontend reports them.
using CounterSink = std::function<void(const std::string& name, double value)>;

// What every frontend takes besides scans, and what it reports.
class FrontendBase {
 public:
  virtual ~FrontendBase() = default;

  // An IMU sample: angular velocity [rad/s] in the IMU frame. False if refused (not after the
  // previous sample, or not finite): the node waits for scans to be covered by accepted ones.
  virtual bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) = 0;
  // A wheel-odometry sample. False if refused (not after the previous one, or not finite).
  virtual bool add_odometry(const OdometrySample& odometry) = 0;
  // Bytes held by the map or maps.
  virtual std::size_t map_bytes() const = 0;
  // Reports every status counter to `sink`.
  virtual void report(const CounterSink& sink) const = 0;
};

class Frontend : public FrontendBase {
 public:
  // One result per scan, in the order the scans come; a result may be an earlier scan's (its
  // utime says which) or none yet (kHeld).
  virtual FrontendResult process(const Scan& scan) = 0;
  // The end of the stream: the pose of a scan still held, if any.
  virtual std::optional<FrontendResult> finish() = 0;
};

// The frontend the config describes (see the header).
std::unique_ptr<Frontend> make_frontend(const FrontendConfig& config);

}  // namespace traverse::frontend
