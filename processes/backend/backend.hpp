// The backend of seed 000 (Karto's mapper and SPA, fed by Hector's trajectory) with the marginal
// covariances of seed 004, as one algorithm without messaging:
//   1. the frontend's dense poses are smoothed: the jumps it makes when it recovers at a loop are
//      replaced by the average of the preceding steps (trajectory_prep.hpp);
//   2. key poses are picked from them (about three per second, or by distance and angle), and
//      their scans are kept at reduced density (scan_store.hpp);
//   3. each new key pose is linked to the previous one by correlative matching (Olson 2009) of its
//      scan against the last few key scans, searched around the frontend's relative motion with a
//      penalty for straying from it (correlative_matcher.hpp);
//   4. loops are closed with the best of all nearby current scans (loop_closer.hpp);
//   5. the pose graph is optimised by Sparse Pose Adjustment (spa.hpp) and the marginal
//      covariance of every key pose is recovered from its sparse Cholesky factor.
// Frontend poses are T_map_base (the frontend's map frame); key poses are T_world_base in the
// backend's frame, which starts equal to the smoothed frontend frame (first key pose fixed).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "correlative_matcher.hpp"
#include "loop_closer.hpp"
#include "pose_config.hpp"
#include "pose_graph.hpp"
#include "scan_store.hpp"
#include "spa.hpp"
#include "trajectory_prep.hpp"

namespace traverse::backend {

struct BackendConfig {
  Pose2Config T_base_laser;  // the horizontal scanner in the base frame
  JumpSmoothingConfig smoothing;
  KeyPoseConfig key_poses;
  ScanStoreConfig scans;
  // Links between consecutive key poses: a narrow search around the frontend's relative motion
  // with a mild penalty, then point-to-line refinement, so that a link can correct a frontend
  // that went wrong (office-s1, offline, seed 1: 1.33 mm position RMSE against 3.36 mm for the
  // frontend alone, which strays 0.2 m there for a while).
  CorrelativeMatcherConfig link{.resolution_m = 0.02,
                                .coarse_factor = 8,
                                .angle_step_rad = 0.003,
                                .linear_window_m = 0.2,
                                .angular_window_rad = 0.06,
                                .kernel_sigma_m = 0.03,
                                .penalty_sigma_xy_m = 0.2,
                                .penalty_sigma_theta_rad = 0.1,
                                .covariance_response_drop = 0.05,
                                .covariance_window_cells = 8,
                                .max_query_points = 400};
  // ... then refined point to line (scan_refiner.hpp); the link keeps the correlative covariance.
  RefinerConfig link_refine;
  int link_chain_length = 5;               // previous key scans a new key scan is matched against
  double min_link_response = 0.35;         // below: the frontend's relative motion is used instead
  double fallback_sigma_xy_m = 0.05;       // its standard deviation [m]
  double fallback_sigma_theta_rad = 0.02;  // [rad]
  // The frontend's relative motion between consecutive key poses as a second edge beside the
  // matched one, with these standard deviations (0: no such edge). A scan-to-map frontend is
  // usually more precise over 1/3 s than a correlative match on a centimetre grid; this edge
  // keeps its precision while matching and loop closures correct the drift. configs/backend.yaml
  // trusts the office cart's frontend more: the simulated office routes measured it at about 1 mm
  // position RMSE over 300 m, and its heading errs by 7e-5 rad rms over a key step but only 9e-5
  // rad rms over whole routes, where a chain of 1,600 edges at 5e-6 rad allows 2e-4 rad: so
  // 0.001 m and 5e-6 rad there (the heading sigma models the drift, not the step noise). With
  // 2e-4 rad per edge the loop closures (heading errors 1.2e-4 rad rms) bent the trajectory:
  // office-s3 1.50 mm position RMSE against 0.97 mm with 5e-6 rad and 1.02 mm for the frontend
  // alone (offline, seed 1).
  double frontend_sigma_xy_m = 0.003;        // [m]
  double frontend_sigma_theta_rad = 0.0005;  // [rad]
  LoopCloserConfig loop;
  SpaConfig spa;
  int optimize_every = 1;       // key poses between optimisations (always at a closure)
  int max_pending_scans = 500;  // scans kept while waiting for their pose (~35 KB each)

  template <class V>
  void visit(V& v) {
    v("T_base_laser", T_base_laser);
    v("smoothing", smoothing);
    v("key_poses", key_poses);
    v("scans", scans);
    v("link", link);
    v("link_refine", link_refine);
    v("link_chain_length", link_chain_length);
    v("min_link_response", min_link_response);
    v("fallback_sigma_xy_m", fallback_sigma_xy_m);
    v("fallback_sigma_theta_rad", fallback_sigma_theta_rad);
    v("frontend_sigma_xy_m", frontend_sigma_xy_m);
    v("frontend_sigma_theta_rad", frontend_sigma_theta_rad);
    v("loop", loop);
    v("spa", spa);
    v("optimize_every", optimize_every);
    v("max_pending_scans", max_pending_scans);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const BackendConfig& config);

struct KeyPose {
  int64_t utime = 0;      // [us] time of the frontend pose (its scan's last point)
  double travel_m = 0.0;  // [m] distance along the smoothed trajectory
  // Marginal covariance of (x [m], y [m], theta [rad]) in the world frame: m^2, m rad, rad^2.
  // Zero for the first key pose (it fixes the gauge).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

struct BackendUpdate {
  int optimisation = 0;                   // 1 for the first optimisation, +1 each
  std::vector<int> new_key_poses;         // key pose indices added since the previous update
  std::vector<LoopClosure> new_closures;  // closures added since the previous update
  SpaResult spa;
  double optimisation_s = 0.0;  // [s] wall time of SPA
  double marginals_s = 0.0;     // [s] wall time of the covariance recovery
};

struct BackendCounters {
  long poses = 0;                   // frontend poses received
  long jumps_smoothed = 0;          // frontend steps replaced by the average
  long outliers_replaced = 0;       // single frontend poses replaced by their neighbours' average
  long scans = 0;                   // scans received
  long key_poses_without_scan = 0;  // key pose deferred: its scan was missing
  long links_matched = 0;           // consecutive links from correlative matching
  long links_refined = 0;           // ... of which refined point to line
  long links_fallback = 0;          // ... from the frontend's motion (response too low)
  long optimisations = 0;
  long optimisations_failed = 0;      // not converged or covariance not recovered
  double last_optimisation_s = 0.0;   // [s]
  double total_optimisation_s = 0.0;  // [s]
};

class Backend {
 public:
  // The config must pass validate().
  explicit Backend(BackendConfig config);

  // A scan of the horizontal scanner (before its frontend pose arrives).
  void add_scan(PlanarScan scan);
  // The frontend pose of the scan ending at `utime`; returns an update when the graph was
  // optimised. Each pose is taken in when the next one arrives (or at finish()): only then can it
  // be told apart from an outlier.
  std::optional<BackendUpdate> add_pose(int64_t utime, const Pose2& T_map_base);
  // End of data: closes an open loop-closure episode and optimises if anything is new.
  std::optional<BackendUpdate> finish();

  const PoseGraph& graph() const { return graph_; }
  const std::vector<KeyPose>& key_poses() const { return key_poses_; }
  const ScanStore& scans() const { return scans_; }
  const std::vector<LoopClosure>& closures() const { return closures_; }
  const LoopCloserCounters& loop_counters() const { return loop_.counters(); }
  const BackendCounters& counters() const { return counters_; }
  int analyses() const { return spa_.system().analyses(); }
  int orderings_reused() const { return spa_.system().orderings_reused(); }

 private:
  Pose2 smooth(int64_t utime, const Pose2& T_map_base);
  // Whether the held pose is an outlier that `next` returns from (see smooth_jumps).
  bool is_outlier(const StampedPose& held, const StampedPose& next) const;
  std::optional<BackendUpdate> take_pose(int64_t utime, const Pose2& T_map_base);
  // Adds the key pose at the newest smoothed pose with the points of `scan`.
  void add_key_pose(const PlanarScan& scan);
  void add_closure(const LoopClosure& closure);
  std::optional<BackendUpdate> optimise();

  BackendConfig config_;
  Pose2 T_base_laser_;
  CorrelativeMatcher link_matcher_;
  ScanRefiner link_refiner_;
  LoopCloser loop_;
  SpaOptimizer spa_;
  BackendCounters counters_;

  std::deque<PlanarScan> pending_scans_;
  std::optional<StampedPose> held_;     // the newest frontend pose, not yet taken in
  int64_t last_key_input_utime_ = 0;    // [us] time of the last pose taken in
  std::vector<StampedPose> tail_;       // the last smoothed poses (window + 1)
  Pose2 last_raw_;                      // the previous frontend pose
  std::vector<StampedPose> since_key_;  // smoothed poses since the last key pose (inclusive)
  double travel_m_ = 0.0;

  PoseGraph graph_;
  std::vector<KeyPose> key_poses_;
  Pose2 last_key_smoothed_;  // smoothed pose of the last key pose
  ScanStore scans_;
  std::vector<LoopClosure> closures_;
  int first_unreported_key_ = 0;
  std::size_t first_unreported_closure_ = 0;
  int optimisations_ = 0;
};

}  // namespace traverse::backend
