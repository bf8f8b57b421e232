// The backend of seed 000 (Karto's mapper and SPA, fed by Hector's trajectory) with the marginal
// covariances of seed 004, as one algorithm without messaging:
//   1. the frontend's poses are prepared for the input they come from: a scanner's stream has its
//      jumps at loops smoothed away, a log subsampled by travel is taken as it is
//      (trajectory_prep.hpp);
//   2. key poses are picked from them (about three per second, or by distance and angle), and
//      their scans are kept at reduced density (scan_store.hpp);
//   3. each new key pose is linked to the previous one by the frontend's relative motion, with
//      the covariance the frontend published for both poses, and by correlative matching (Olson
//      2009) of its scan against the last few key scans, searched around the frontend's relative
//      motion with a penalty for straying from it (correlative_matcher.hpp);
//   4. loops are closed with the best of all nearby current scans (loop_closer.hpp);
//   5. the pose graph is optimised by Sparse Pose Adjustment (spa.hpp) and the marginal
//      covariance of every key pose is recovered from its sparse Cholesky factor;
//   6. optionally, the horizontal scanner's boresight is estimated from the optimised key poses
//      and the whole published trajectory is turned back by it (boresight.hpp).
// Frontend poses are T_map_base (the frontend's map frame); key poses are T_world_base in the
// backend's frame, which starts equal to the prepared frontend frame (first key pose fixed).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "boresight.hpp"
#include "correlative_matcher.hpp"
#include "loop_closer.hpp"
#include "odometry_check.hpp"
#include "pose_config.hpp"
#include "pose_graph.hpp"
#include "scan_store.hpp"
#include "spa.hpp"
#include "start_frame.hpp"
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
  int link_chain_length = 5;  // previous key scans a new key scan is matched against
  // A link whose refinement leaves a direction open (a bare corridor's axis: an eigenvalue of the
  // refiner's information below this share of the largest, heading weighed as the arc it moves
  // the points through; common/degeneracy.hpp) is held there at the wheel odometry's step, with
  // the odometry's variance, as the frontend holds its match (its own covariance stays on the
  // other directions), where that step agrees with the frontend's within the odometry's error
  // model (a log whose odometry restarts, as the subsampled CARMEN logs', is not held); otherwise
  // it is opened there by the variance its information allows, at most link_open_sigma_m. Only
  // on a scanner's stream, over key steps of at most half a second: on a log subsampled by travel
  // consecutive key scans lie metres apart and the links stay as matched (held there, the CARMEN
  // logs' RPE over 10 m gained 0.2-2.4 mm and their position RMSE lost up to 47 mm). The
  // correlative response surface is bounded by its window and claims centimetres along such an
  // axis, and consecutive key scans of a corridor match short or long by centimetres; the
  // frontend's edges carry nothing there (its covariance along a held axis is the prediction's,
  // grown over the corridor). 0: never held or opened. Realistic simulator, full graph (README):
  // corridor-return seeds 1-3 0.113 / 0.172 / 0.117 m
  // -> 0.021 / 0.020 / 0.047 m with the start frame below.
  double link_degeneracy_min_ratio = 0.0;
  double link_open_sigma_m = 10.0;  // [m] of point motion
  // Below this response no link edge; without a frontend edge the frontend's relative motion
  // stands in, with the fallback sigmas.
  double min_link_response = 0.35;
  // The match's covariance (the spread of its response surface) times this [unitless].
  double link_covariance_scale = 1.0;
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
  // How the frontend's trajectory enters the graph (frontend_chain.hpp): each key pose's error
  // is the covariance the frontend published for it (times frontend_covariance_scale; the fixed
  // sigmas above stand in for a pose published without one, or for all with
  // frontend_covariance false), and the frontend's map drifts by as much as one such error over
  // frontend_drift_length_m of travel (a random walk). 0: no drift model, the frontend's motion
  // between consecutive key poses is an edge with both poses' covariances.
  bool frontend_covariance = true;
  double frontend_covariance_scale = 1.0;  // [unitless]
  double frontend_drift_length_m = 0.0;    // [m]
  // Two errors no edge of the graph can hold, added to the marginal covariances the backend
  // publishes (published_covariance) and not to the optimisation, whose optimum neither moves:
  // the frame's own heading, which the first key pose fixes through the horizontal scanner's
  // boresight calibration (a rotation of the whole graph about the first key pose: the absolute
  // position error grows with the distance from there; relative poses keep none of it), and each
  // key pose's error against the moment it is stamped with (sensor clocks: the cart moves on
  // while a stamp is late). 0: none. While the boresight (below) is estimated and applied, the
  // frame's heading errs by what the estimate errs: its standard deviation takes the place of
  // frame_heading_sigma_rad.
  double frame_heading_sigma_rad = 0.0;  // [rad]
  double key_pose_sigma_xy_m = 0.0;      // [m]
  // The graph's marginals, and the information of the edges it publishes, are published this
  // many times too large (too small): the edges' covariances calibrated at once against the
  // errors they allow (configs/backend.yaml has the fit). One factor on every edge of the graph
  // does not move its optimum; the loop closer's check keeps the unscaled marginals, so nothing
  // the backend estimates changes with it.
  double marginal_scale = 1.0;  // [unitless]
  // The published marginals come from the graph at its optimum with every edge of the frontend's
  // chain (kFrontend, kFrontendDrift, kFrontendPose) this many times less informative than the
  // optimisation weighs it (a variance factor; the links and closures as they are, their scales
  // are fitted against real references). The frontend's published covariances are far too small
  // against its real error (configs/backend.yaml), so in the graph as optimised its chain
  // outweighs any closure and a closure cannot shrink a marginal; scaled after the fact
  // (marginal_scale) the marginals then stay as large after a closure as before. Computed on a
  // copy of the graph's information, so neither the optimum nor the loop closer's check (which
  // keeps KeyPose::covariance) moves. 1: the graph's own marginals, one factorisation fewer.
  double marginal_frontend_scale = 1.0;  // [unitless]
  // The horizontal scanner's yaw on the cart, estimated from the key poses and applied to every
  // published key pose (boresight.hpp).
  BoresightConfig boresight;
  // The frontend's map held against the first key scan: a turn the map took while it was built
  // is taken out of the published key poses before the boresight's (start_frame.hpp).
  StartFrameConfig start_frame;
  // Wheel odometry, when there is any, as a check on each frontend step (odometry_check.hpp).
  OdometryCheckConfig odometry;
  LoopCloserConfig loop;
  // A closure is added to a copy of the graph and both are optimised: if the graph's chi2 grows
  // by more than this, the closure contradicts the graph and is left out (0: not checked). For a
  // closure that agrees with the graph, the growth follows a chi-square law with 3 degrees of
  // freedom (99.9 %: 16.3).
  double closure_max_chi2_increase = 0.0;
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
    v("link_degeneracy_min_ratio", link_degeneracy_min_ratio);
    v("link_open_sigma_m", link_open_sigma_m);
    v("link_covariance_scale", link_covariance_scale);
    v("fallback_sigma_xy_m", fallback_sigma_xy_m);
    v("fallback_sigma_theta_rad", fallback_sigma_theta_rad);
    v("frontend_sigma_xy_m", frontend_sigma_xy_m);
    v("frontend_sigma_theta_rad", frontend_sigma_theta_rad);
    v("frontend_covariance", frontend_covariance);
    v("frontend_covariance_scale", frontend_covariance_scale);
    v("frontend_drift_length_m", frontend_drift_length_m);
    v("frame_heading_sigma_rad", frame_heading_sigma_rad);
    v("key_pose_sigma_xy_m", key_pose_sigma_xy_m);
    v("marginal_scale", marginal_scale);
    v("marginal_frontend_scale", marginal_frontend_scale);
    v("boresight", boresight);
    v("start_frame", start_frame);
    v("odometry", odometry);
    v("loop", loop);
    v("closure_max_chi2_increase", closure_max_chi2_increase);
    v("spa", spa);
    v("optimize_every", optimize_every);
    v("max_pending_scans", max_pending_scans);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const BackendConfig& config);

struct KeyPose {
  int64_t utime = 0;      // [us] time of the frontend pose (its scan's last point)
  Pose2 T_world_base;     // the estimate of the last optimisation (or the first guess)
  double travel_m = 0.0;  // [m] distance along the smoothed trajectory
  // Marginal covariance of (x [m], y [m], theta [rad]) in the world frame: m^2, m rad, rad^2.
  // Zero for the first key pose (it fixes the gauge).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  // The same with the frontend's chain at marginal_frontend_scale (BackendConfig): what is
  // published (Backend::published_covariance).
  Eigen::Matrix3d calibrated_covariance = Eigen::Matrix3d::Zero();
};

// What an edge of the backend's graph measures.
enum class EdgeKind {
  kLink,           // correlative match of a key scan against the last few (or its fallback)
  kFrontend,       // the frontend's relative motion between consecutive key poses
  kFrontendDrift,  // ... between consecutive poses of the drifting frontend (frontend_chain.hpp)
  kFrontendPose,   // a key pose against the drifting frontend's pose (frontend_chain.hpp)
  kClosure,        // a loop closure
};

// Whether an edge of this kind carries the frontend's trajectory (marginal_frontend_scale).
inline bool frontend_chain(EdgeKind kind) {
  return kind == EdgeKind::kFrontend || kind == EdgeKind::kFrontendDrift ||
         kind == EdgeKind::kFrontendPose;
}

// An edge between two key poses (key pose indices, not graph vertices), as published
// (backend_node.hpp): links and closures as in the graph; the frontend's edges of a key step (with
// the drift model: the drifting frontend's step and its pose edge) as one edge of the frontend's
// motion (frontend_chain.hpp, key_step_edge).
struct KeyEdge {
  int from = 0, to = 0;                                       // key pose indices
  EdgeKind kind = EdgeKind::kLink;                            // kLink, kFrontend or kClosure
  Pose2 T_from_to;                                            // pose of `to` in the frame of `from`
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();  // 1/m^2, 1/(m rad), 1/rad^2
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
  TrajectoryPrepCounters prep;      // frontend poses received, dropped, smoothed
  long scans = 0;                   // scans received
  long key_poses_without_scan = 0;  // key pose deferred: its scan was missing
  long links_matched = 0;           // consecutive links from correlative matching
  long links_refined = 0;           // ... of which refined point to line
  long links_fallback = 0;          // ... from the frontend's motion (response too low)
  long links_opened = 0;            // ... refined, with a direction left open (degenerate)
  long links_held = 0;              // ... of which held there at the odometry's step
  // Frontend steps the odometry contradicted and the scans matched better at the odometry's
  // (odometry_check.hpp): replaced by the odometry's.
  long frontend_steps_replaced = 0;
  // ... where the next step was contradicted too and the frontend's motion over both agreed with
  // the odometry's (a spike at one key pose): that step took the frontend's net motion over both.
  long frontend_spikes_netted = 0;
  long closures_rejected_inconsistent = 0;  // closures the trial optimisation refused
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
  // A wheel odometry reading: the base in the drifting odom frame (before the frontend poses of
  // its time arrive).
  void add_odometry(int64_t utime, const Pose2& T_odom_base) { odometry_.add(utime, T_odom_base); }
  // The frontend pose of the scan ending at `utime`; returns an update when the graph was
  // optimised. Each pose is taken in when the next one arrives (or at finish()): only then can it
  // be told apart from an outlier.
  // `covariance`: the frontend's, of (x [m], y [m], theta [rad]) in its map frame (zero: unknown).
  std::optional<BackendUpdate> add_pose(
      int64_t utime, const Pose2& T_map_base,
      const Eigen::Matrix3d& covariance = Eigen::Matrix3d::Zero());
  // End of data: closes an open loop-closure episode and optimises if anything is new.
  std::optional<BackendUpdate> finish();

  // The pose graph: besides the key poses (vertex key_vertex(i) for key pose i) it may hold the
  // drifting frontend's poses (frontend_chain.hpp).
  const PoseGraph& graph() const { return graph_; }
  int key_vertex(int key) const { return drift_model_ ? 2 * key : key; }
  // The key pose of a vertex, -1 for the drifting frontend's.
  int key_of_vertex(int vertex) const {
    return drift_model_ ? (vertex % 2 == 0 ? vertex / 2 : -1) : vertex;
  }
  // The kind of each edge of graph().edges, in the same order.
  const std::vector<EdgeKind>& edge_kinds() const { return edge_kinds_; }
  // The graph's edges between key poses only, in the order they were added (KeyEdge).
  const std::vector<KeyEdge>& key_edges() const { return key_edges_; }
  const BackendConfig& config() const { return config_; }
  const std::vector<KeyPose>& key_poses() const { return key_poses_; }
  // Key pose i as published: KeyPose::T_world_base (the graph's frame, in which the scans were
  // matched) turned back about the first key pose by the turn the frontend's map took against the
  // first key scan (start_frame.hpp), then its position by the scanner's boresight (boresight.hpp),
  // each when it is estimated; the same pose otherwise.
  Pose2 published_pose(int i) const;
  // Key pose i's covariance as published: its calibrated marginal (KeyPose::
  // calibrated_covariance; the loop closer's check uses KeyPose::covariance) times marginal_scale,
  // with the frame's heading (frame_heading_sigma_rad, or the boresight estimate's standard
  // deviation while it is applied) and the key pose's own error (key_pose_sigma_xy_m); in the
  // published frame. Zero for the first key pose.
  Eigen::Matrix3d published_covariance(int i) const;
  const Boresight& boresight() const { return boresight_; }
  const StartFrame& start_frame() const { return start_frame_; }
  const ScanStore& scans() const { return scans_; }
  const std::vector<LoopClosure>& closures() const { return closures_; }
  const LoopCloserCounters& loop_counters() const { return loop_.counters(); }
  const OdometryCounters& odometry_counters() const { return odometry_.counters(); }
  const BackendCounters& counters() const { return counters_; }
  // Why the frontend's poses gave no trajectory, in words; empty when they did. Stamps that carry
  // no time (all equal, or mostly not later than the pose before) leave one key pose of many
  // poses: that is a failure to report, not a one-pose result.
  std::string input_fault() const;
  int analyses() const { return spa_.system().analyses(); }
  int orderings_reused() const { return spa_.system().orderings_reused(); }

 private:
  friend class BackendStateStore;  // backend_state.hpp: saves and restores the members below
  std::optional<BackendUpdate> take_pose(const PreparedPose& pose);
  // Whether the frontend's relative motion enters the graph as edges of its own.
  bool frontend_edges() const {
    return config_.frontend_sigma_xy_m > 0.0 && config_.frontend_sigma_theta_rad > 0.0;
  }
  // A copy of the graph with the frontend's chain at marginal_frontend_scale.
  PoseGraph calibrated_graph() const;
  // Adds the key pose at the newest prepared pose with the points of `scan`.
  void add_key_pose(const PlanarScan& scan);
  // The frontend's covariances of the last key pose and the newest prepared pose, each in its own
  // frame (frontend_chain.hpp).
  std::pair<Eigen::Matrix3d, Eigen::Matrix3d> frontend_covariances() const;
  // Adds the frontend's edges of the new key pose `key` (frontend_chain.hpp); `odometry`: the
  // odometry's step when it rejected the frontend's, which then takes its place.
  void add_frontend_edges(int key, const std::optional<OdometryStep>& odometry);
  // After the odometry replaced the last key step (`step_before`) and contradicts this one too:
  // the frontend's net motion over both, as this step's (step_before^-1 * net), when that net
  // agrees with the odometry's over the same interval; nullopt otherwise. A frontend that places
  // one key pose off and the next back (a spike) keeps its net motion; a frontend that slipped
  // stays replaced.
  std::optional<OdometryStep> spike_net_step(const PreparedPose& now, const Pose2& step_before,
                                             const Eigen::Matrix3d& step_covariance) const;
  // The step from the last key pose to a new one (key_link.cpp).
  struct KeyStep {
    Pose2 motion;  // the frontend's relative motion, or the odometry's or the net that replaced it
    // The odometry's step where it replaced the frontend's, its covariance widened by the two
    // steps' disagreement (key_link.cpp says why).
    std::optional<OdometryStep> odometry;
    bool netted = false;       // ... the frontend's net motion over a spike
    std::optional<Edge> link;  // the link edge: matched, or the fallback
  };
  // The link of the new key pose `index` (its points in the base frame, its prepared pose
  // `now`): matched against the last link_chain_length key scans, the frontend's step checked
  // against the odometry, refined and held along open directions (key_link.cpp).
  KeyStep link_key(int index, const std::vector<Eigen::Vector2f>& points, const PreparedPose& now);
  // A refined link of a scanner's stream (a key step of at most half a second) along the
  // directions its scans leave open (link_degeneracy_min_ratio): held at the odometry's step from
  // the last key pose to `now` where that agrees with the frontend's motion, opened by the
  // refiner's own information otherwise. T_world_key and covariance (world frame) are the link's,
  // changed in place.
  void hold_open_directions(const RefineResult& refined, const PreparedPose& now,
                            const Pose2& T_world_from, const Pose2& frontend_motion,
                            Pose2& T_world_key, Eigen::Matrix3d& covariance);
  // Adds the closure unless a trial optimisation finds it inconsistent with the graph.
  void add_closure(LoopClosure closure);
  std::optional<BackendUpdate> optimise();

  BackendConfig config_;
  bool drift_model_;  // the frontend's edges follow the drift model (frontend_chain.hpp)
  Pose2 T_base_laser_;
  CorrelativeMatcher link_matcher_;
  ScanRefiner link_refiner_;
  LoopCloser loop_;
  OdometryCheck odometry_;
  SpaOptimizer spa_;
  SpaOptimizer trial_spa_;  // for the graph with a closure on trial
  Boresight boresight_;     // fitted again at every optimisation
  StartFrame start_frame_;  // matched once, taken again at every optimisation
  BackendCounters counters_;

  TrajectoryPrep prep_;
  std::deque<PlanarScan> pending_scans_;
  std::optional<PreparedPose> previous_;  // the prepared pose before the newest
  std::vector<PreparedPose> since_key_;   // prepared poses since the last key pose (inclusive)

  PoseGraph graph_;
  std::vector<EdgeKind> edge_kinds_;  // parallel to graph_.edges
  std::vector<KeyEdge> key_edges_;
  std::vector<KeyPose> key_poses_;
  PreparedPose last_key_;         // prepared pose of the last key pose
  PreparedPose key_before_last_;  // ... and of the one before it
  // The odometry's motion over the last key step, where it replaced the frontend's.
  std::optional<Pose2> step_before_from_odometry_;
  ScanStore scans_;
  std::vector<LoopClosure> closures_;
  int first_unreported_key_ = 0;
  std::size_t first_unreported_closure_ = 0;
  int optimisations_ = 0;
};

}  // namespace traverse::backend
