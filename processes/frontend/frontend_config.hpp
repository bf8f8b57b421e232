// Configuration of the frontend (scan-to-map matcher): one struct per module, defaults here,
// keys listed once in each `visit`. Lengths m, angles rad, times us.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "channels.hpp"
#include "extrinsic_yaw.hpp"
#include "handover_config.hpp"
#include "icp/icp_config.hpp"
#include "pose_config.hpp"

namespace traverse::frontend {

// Occupancy grid pyramid (Hector SLAM section IV.A, map update section IV.C).
struct MapConfig {
  double resolution_m = 0.05;      // finest level; level k has resolution_m * 2^k
  int levels = 3;                  // pyramid depth, 1 = a single grid
  double p_occupied = 0.9;         // probability an end point's cell is occupied (Hector 0.9)
  double p_free = 0.4;             // probability a traversed cell is occupied (Hector 0.4)
  double update_distance_m = 0.2;  // update the map when the pose moved this far ...
  double update_angle_rad = 0.1;   // ... or turned this much since the last update
  // Cells keep where in them the hits fell and the map is read there (occupancy_grid.hpp): walls
  // a small angle off the grid's axes no longer pull the heading onto the axes.
  bool subcell_hits = false;
  // Beyond this, tiles farthest from the pose are dropped: per map, so a sparse-scan ensemble
  // (MatcherConfig::sparse_ensemble_members) holds up to that many times this.
  int64_t max_bytes = 512LL << 20;

  template <class V>
  void visit(V& v) {
    v("resolution_m", resolution_m);
    v("levels", levels);
    v("p_occupied", p_occupied);
    v("p_free", p_free);
    v("update_distance_m", update_distance_m);
    v("update_angle_rad", update_angle_rad);
    v("subcell_hits", subcell_hits);
    v("max_bytes", max_bytes);
  }
};

// Gauss-Newton scan-to-map matching (Hector SLAM section IV.B).
struct MatcherConfig {
  int iterations_coarse = 4;  // Gauss-Newton iterations on every level but the finest
  int iterations_fine = 6;    // on the finest level
  // Points closer than this to the previously kept point along the scan are not matched (0 = all).
  // Fewer points: proportionally faster matching, slightly noisier poses; map updates use all.
  double min_point_spacing_m = 0.02;
  int min_valid_points = 20;  // fewer valid readings: the pose is predicted, not measured
  double min_range_m = 0.1;   // readings outside [min_range_m, max_range_m] are ignored
  double max_range_m = 40.0;  // (and outside the scan's own range_min/range_max)
  // Weak prior pulling towards the motion prediction: keeps directions the geometry does not
  // constrain (a featureless corridor's axis) at the predicted value instead of drifting.
  double prior_sigma_xy_m = 0.5;
  double prior_sigma_theta_rad = 0.2;
  double min_residual_sigma = 0.02;  // floor of the map-value noise used to scale covariances
  // The coarse levels can hand the finer ones a neighbouring basin: along a corridor, whose
  // coarsest grid (4 x resolution_m) blurs the few features along the axis, a scan is carried a
  // coarse cell along it and the fine levels settle there with a worse fit, and the next scan
  // comes back (docs/frontends.md, "A coarse cell along the corridor"). On a driver's stream
  // (each scan with its sweep's duration) whose scans come at most coarse_check_max_gap_us apart
  // (this one, and the median of the last five intervals: the prediction then good to
  // millimetres), a result farther than coarse_check_m [m] from the prediction is matched again
  // from the prediction on the finest level alone, and that match is kept if its fit on the
  // finest grid (RMS of 1 - M) is better by at least the share coarse_check_gain. Not on a log
  // with one stamp per scan (CARMEN): at a few scans a second predictions are off by
  // centimetres, and a logger's stamps may be its arrival times (intel's come in bursts 1 ms
  // apart); there the check only perturbs. 0 m: off.
  double coarse_check_m = 0.05;
  double coarse_check_gain = 0.0;
  int64_t coarse_check_max_gap_us = 50000;
  // Also where the scan leaves a direction open (degeneracy_min_ratio), whose fit is flat along
  // it and which the prediction holds.
  bool coarse_check_open_directions = false;
  // Match each point only across its own surface (hector/surface_normals.hpp): the map's
  // gradient along a wall (where the map's wall ends, a far wall's dotted cells) pulls a
  // corridor's scan along the axis that nothing else holds. Applied only to scans predicted with
  // odometry (HectorFrontend::matcher_for), which then holds that axis (degeneracy_min_ratio):
  // without odometry it lets a corridor slide (corridor-return, IMU alone, with the two keys
  // below: 7.8 m RMSE). Off by default with the two keys below (docs/frontends.md, "The
  // spread").
  bool normal_projection = false;
  // Not a key: Gauss-Newton reads the map at the hits' sub-cell offsets (map.subcell_hits;
  // OccupancyGrid::value's `at_hits`). The frontend sets it per scan: on for a scanner's stream,
  // off for a log subsampled by travel, whose wide search lands metres from the last pose and
  // whose Gauss-Newton then takes poor fits near the search's candidates on the sub-cell map
  // (docs/frontends.md, "Sub-cell hits": the subsampled CARMEN aces log lost with it).
  bool read_at_hits = true;
  // Degeneracy (hector/degeneracy.hpp): eigen-directions of the scan's information (heading
  // weighed as the arc it moves the points through) below this share of the largest are held at
  // the odometry prediction, and take the prediction's covariance. 0 never holds any.
  double degeneracy_min_ratio = 0.0;
  // Hold them also where no odometry predicts the scan, at the prediction of the last poses'
  // velocity, which must then be bounded (motion_prior.max_acceleration_mps2 > 0). Off by
  // default: it holds a robot that drives from rooms into a corridor (the realistic simulator's
  // office-rooms, IMU alone: lost runs of 1.4-6.2 m within 0.47 m), but loses a cart in a 56 m bare
  // corridor that the match's faint grip along the axis holds (corridor-return seed 1: 0.41 ->
  // 17.5 m), and the map made at held poses along a corridor no longer agrees with the matches
  // once the hold lets go (docs/frontends.md, "Open directions without odometry").
  bool degeneracy_hold_without_odometry = false;
  // That hold only where the velocity it holds to was measured: after the scans determined the
  // whole pose for at least degeneracy_hold_after_s without a break (a cart that starts in a bare
  // corridor has only the standstill it started from), and for at most degeneracy_hold_max_s
  // after the last scan that did (0: no limit; the velocity drifts the longer it is held: a cart
  // walking back along the bare corridor it came). 0 and 0 hold as above
  // (hector/open_direction_hold.hpp).
  double degeneracy_hold_after_s = 0.0;
  double degeneracy_hold_max_s = 0.0;
  // On a scanner's stream, points where the map (level 1) holds only cells below this occupancy
  // probability all around, at the predicted pose, are left out of the match and the map
  // (hector/moved_points.hpp: people walking through, mixed pixels). 0 keeps every point. 0.25
  // with the two keys above (0.03, true) wins on every simulated route with odometry (metres on
  // corridor-return, office-s2, office-s3); on the relations log aces it lost 2 of 4 starts a
  // centimetre or a milliradian apart until the odometry check counted only what the scan
  // determines (now 0.040-0.045 m from 5 starts against 0.039-0.041 m off), and the regression
  // log's RMSE was 5 % worse: off (docs/frontends.md, "The spread").
  double moved_max_probability = 0.0;
  // Recovery: when the RMS of 1 - M after Gauss-Newton exceeds this, the prediction was too far
  // off for gradient steps (a fast turn between sparse scans): search exhaustively on the
  // coarsest level within the windows below around the prediction, refine from the best
  // candidate, keep the better result. 1 or more disables the search.
  double search_trigger_residual = 0.35;
  double search_linear_window_m = 1.0;     // +- in x and y
  double search_angular_window_rad = 0.8;  // +-
  // A searched result that lies farther than this from the prediction, in translation or in
  // heading, is kept only if it brings the residual under search_trigger_residual. A scan that
  // fits nowhere well (people next to the scanner, a view the map has not seen) otherwise moves
  // the pose to wherever a part of it fits best: a jump of metres where the prediction, a scanner
  // period ahead, is off by centimetres. The Gauss-Newton result from the prediction stands; if
  // that too ends this far off with a poor fit, the scan gets the prediction (flagged).
  double search_max_unverified_m = 0.5;
  double search_max_unverified_rad = 0.2;
  // Sparse scans: a scan more than wide_search_gap_us after the previous pose (or one in a
  // stream whose last five intervals have a median above it: such logs repeat timestamps) does
  // not come from a scanner's stream but from a log subsampled by travel (the CARMEN sets: 0.5
  // to 1.8 m and up to 80 degrees between scans, no odometry). Constant velocity predicts such a
  // step poorly, so it is always matched by a wide correlative search (branch and bound) around
  // the prediction (the average step of the last scans) within the windows below, then
  // Gauss-Newton from the best pose.
  int64_t wide_search_gap_us = 500000;
  double wide_search_linear_window_m = 2.0;  // +- in x and y
  // +-; 80 degree turns between scans and a prediction 60 degrees off happen in the CARMEN sets.
  double wide_search_angular_window_rad = 2.5;
  // [summed evidence, 1 per point on an occupied cell] The covariance of a sparse scan's pose
  // adds the spread of the wide search's score surface (wide_search.hpp): a pose scoring this
  // much below the best counts e times less likely. It is what shows a step along a corridor that
  // the scan cannot tell, or a second pose that fits about as well; the Gauss-Newton covariance
  // alone sees only the curvature at the pose it ended on (millimetres where such a step was 0.7
  // m off). With 3 the median normalised error of a step on the CARMEN sets intel, aces and
  // csail is below that of a consistent estimate, while 1 to 10 % of steps (not 1 %) fall outside
  // their 99 % ellipse: the errors have heavier tails (tests/frontend/carmen_test.cpp). 0 leaves
  // the spread out.
  double wide_search_temperature = 3.0;
  // Sparse scans are matched by this many frontends at once, each with its own map whose grid
  // is offset from the others' by a fraction of a cell and turned by under a degree; each scan's
  // published step is the one most of them agree on (within 0.15 m and 0.05 rad), and the spread
  // of their steps is added to its covariance. On a sparse log the outcome of one frontend turns
  // on such offsets: on CARMEN aces, from 8 offsets, one frontend jumps 0.67 to 2.0 m and 3 times
  // loses track (RPE over 10 m 1.5 to 2.2 m); the members mostly go wrong at different scans, and
  // five of them jump 0.20 to 0.88 m (7 of 8 under 0.5 m) with RPE over 10 m at most 0.24 m
  // (scripts/frontend-sensitivity.sh aces, --members 1). Steps most members misjudge together
  // remain (intel scan 761, 0.87 m, until sparse_lag). Costs this many times the sparse path's
  // time; a scanner's stream (three scans in a row that are not sparse) drops the extra members.
  // 1 runs one frontend.
  int sparse_ensemble_members = 5;
  // Prior on the shape of a sparse scan's step (wide_search.hpp, StepPrior), from this frontend's
  // last pose: a log subsampled by travel rarely steps both under sparse_step_min_travel_m and
  // under sparse_step_min_turn_rad (the CARMEN sets keep a scan after about 1 m or 0.5 rad; 45 of
  // intel's 909 and 23 of aces' 439 reference steps are under 0.8 m and 0.4 rad), and a wheeled
  // platform's step lies on the arc through its turn (1 of intel's, 2 of aces' and 5 of csail's 405
  // reference steps are more than 0.3 m sideways off it or backwards). Each term costs up to its
  // weight per point, against evidence of 2 per point between an occupied and a free cell. It is
  // what keeps a frontend from stalling where the scan fits the last pose as well as the next
  // (along a corridor) or sliding sideways: on aces the largest jump falls from 1.03 to 0.22 m and
  // the RPE over 10 m from 0.47 to 0.15 m (scripts/eval-carmen.sh aces --stages frontend, both
  // weights 0 and as shipped). It holds only for a log subsampled by travel (the median of the last
  // five intervals above wide_search_gap_us), not for a pause in a scanner's stream, where the
  // platform stood still.
  // A weight of 0 leaves its term out; a platform that may step sideways or backwards between
  // sparse scans (a hand-held scanner) needs sparse_step_off_arc_weight 0.
  double sparse_step_min_travel_m = 0.8;
  double sparse_step_min_turn_rad = 0.4;
  double sparse_step_short_weight = 0.2;
  double sparse_step_off_arc_free_m = 0.2;
  double sparse_step_off_arc_weight = 0.1;
  // Sparse lag: on a log subsampled by travel (as for the step prior) the frontend runs one scan
  // behind, so that the scan after can still move a scan's pose. Where a scan fits a map
  // that an earlier pass made otherwise (a door then open, that pass's drift) better at a wrong
  // pose, the next scan usually lands right again, and the pair of steps shows it: once scan
  // k+1 is matched, scan k's pose is compared with the best pose within sparse_lag_window_m
  // and sparse_lag_window_rad of the pose halfway between scans k-1 and k+1 (if it lies
  // outside that window), both scored without scan k in the map: evidence per point minus the
  // step prior of the steps into and out of the pose, minus sparse_lag_long_weight per point
  // at 0.3 m beyond 1.25 times the log's usual step (90th percentile of the last 30). The
  // other pose is taken if it scores sparse_lag_margin per point more; scan k's map update then
  // moves (undone exactly, map and motion model alike), and scan k+1 is matched again. On
  // intel, scan 761 was matched 0.73 m short and 20 degrees off (the largest jump, 0.87 m); the
  // lag moves it and the largest jump is 0.45 m (scripts/eval-carmen.sh intel --stages frontend,
  // with and without). The frontend publishes each pose one scan late on such logs (a second
  // there); false gives each pose at once.
  bool sparse_lag = true;
  double sparse_lag_window_m = 0.3;
  double sparse_lag_window_rad = 0.2;
  double sparse_lag_long_weight = 0.2;  // [per point]
  double sparse_lag_margin = 0.1;       // [per point, evidence -1 to 1]
  // Sparse widening (sparse/widen.hpp): a sparse scan (without odometry) whose match fits worse
  // than sparse_widen_evidence_ratio times the median evidence of the last sparse matches is
  // searched again in windows sparse_widen_factor times wider, up to sparse_widen_max_window_m
  // (+- in x and y), and moved where a wider window fits it as well as usual and sparse_lag_margin
  // per point better than before. A step of 3 m where the log usually steps 0.6 m
  // (tests/carmen/long_step_test.cpp). 0 for the ratio turns it off.
  double sparse_widen_evidence_ratio = 0.7;
  double sparse_widen_factor = 2.0;
  double sparse_widen_max_window_m = 8.0;  // [m]

  template <class V>
  void visit(V& v) {
    v("iterations_coarse", iterations_coarse);
    v("iterations_fine", iterations_fine);
    v("min_point_spacing_m", min_point_spacing_m);
    v("min_valid_points", min_valid_points);
    v("min_range_m", min_range_m);
    v("max_range_m", max_range_m);
    v("prior_sigma_xy_m", prior_sigma_xy_m);
    v("prior_sigma_theta_rad", prior_sigma_theta_rad);
    v("min_residual_sigma", min_residual_sigma);
    v("coarse_check_m", coarse_check_m);
    v("coarse_check_gain", coarse_check_gain);
    v("coarse_check_max_gap_us", coarse_check_max_gap_us);
    v("coarse_check_open_directions", coarse_check_open_directions);
    v("normal_projection", normal_projection);
    v("degeneracy_min_ratio", degeneracy_min_ratio);
    v("degeneracy_hold_without_odometry", degeneracy_hold_without_odometry);
    v("degeneracy_hold_after_s", degeneracy_hold_after_s);
    v("degeneracy_hold_max_s", degeneracy_hold_max_s);
    v("moved_max_probability", moved_max_probability);
    v("search_trigger_residual", search_trigger_residual);
    v("search_linear_window_m", search_linear_window_m);
    v("search_angular_window_rad", search_angular_window_rad);
    v("search_max_unverified_m", search_max_unverified_m);
    v("search_max_unverified_rad", search_max_unverified_rad);
    v("wide_search_gap_us", wide_search_gap_us);
    v("wide_search_linear_window_m", wide_search_linear_window_m);
    v("wide_search_angular_window_rad", wide_search_angular_window_rad);
    v("wide_search_temperature", wide_search_temperature);
    v("sparse_ensemble_members", sparse_ensemble_members);
    v("sparse_step_min_travel_m", sparse_step_min_travel_m);
    v("sparse_step_min_turn_rad", sparse_step_min_turn_rad);
    v("sparse_step_short_weight", sparse_step_short_weight);
    v("sparse_step_off_arc_free_m", sparse_step_off_arc_free_m);
    v("sparse_step_off_arc_weight", sparse_step_off_arc_weight);
    v("sparse_lag", sparse_lag);
    v("sparse_lag_window_m", sparse_lag_window_m);
    v("sparse_lag_window_rad", sparse_lag_window_rad);
    v("sparse_lag_long_weight", sparse_lag_long_weight);
    v("sparse_lag_margin", sparse_lag_margin);
    v("sparse_widen_evidence_ratio", sparse_widen_evidence_ratio);
    v("sparse_widen_factor", sparse_widen_factor);
    v("sparse_widen_max_window_m", sparse_widen_max_window_m);
  }
};

// Motion compensation within a sweep (seed 000 section 2).
struct DeskewConfig {
  bool enabled = true;      // rotate each point by the heading change at its own time
  bool translation = true;  // also shift it by the constant-velocity translation
  // Orientation of the IMU in the base frame (R_base_imu = Rz(yaw) Ry(pitch) Rx(roll)).
  double imu_roll_rad = 0.0;
  double imu_pitch_rad = 0.0;
  double imu_yaw_rad = 0.0;
  // A scan waits at most this long (in scan time) for IMU samples covering its last point.
  int64_t imu_wait_us = 100000;

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("translation", translation);
    v("imu_roll_rad", imu_roll_rad);
    v("imu_pitch_rad", imu_pitch_rad);
    v("imu_yaw_rad", imu_yaw_rad);
    v("imu_wait_us", imu_wait_us);
  }
};

// The motion prior (motion_prior.hpp): what predicts each scan's pose besides the last poses.
struct MotionPriorConfig {
  // imu | odometry | both | none. both: translation by wheel odometry, rotation by the IMU where
  // its samples cover the step, else by odometry; odometry: both by odometry; imu: rotation by
  // the IMU, translation by the velocity of the last poses; none: the last poses alone. What the
  // source names but the stream does not carry (no odometry, the IMU silent) falls back to the
  // next of these, counted in the status (odometry_missing, _gap, _stale). A rig without
  // odometry or IMU runs alike under every value.
  std::string source = "both";
  // Odometry samples further apart than this around a time do not give the pose at it (the
  // odometry stopped or lost messages): the prediction falls back.
  int64_t odometry_max_gap_us = 1'000'000;
  // A scan up to this after the newest odometry sample is predicted at the newest rate (the
  // sample behind a scan's last point, odometry arriving late); later, the prediction falls back.
  int64_t odometry_max_extrapolation_us = 200'000;
  // Standard deviation of an odometry step, added to what the messages' covariance says:
  // a constant, per metre travelled and per radian turned (a Pioneer's wheels: a few cm per
  // metre, several degrees per turn where the floor lets them slip).
  double odometry_sigma_xy_m = 0.02;
  double odometry_sigma_xy_per_m = 0.1;
  double odometry_sigma_theta_rad = 0.01;
  double odometry_sigma_theta_per_m = 0.05;
  double odometry_sigma_theta_per_rad = 0.1;
  // With odometry, the wide search (sparse scans) and the recovery search (a failed match) are
  // centred on the odometry prediction and span search_sigmas of its step's standard deviation,
  // at least search_min_linear_m and search_min_angular_rad, at most the matcher's windows; the
  // recovery search then also leaves out the last pose (odometry says whether the base moved).
  double search_sigmas = 3.0;
  // [RMS of 1 - M, unitless] Odometry's prediction is checked against the scan on a scanner's
  // stream: where the prediction without odometry (IMU and the last poses) differs from it by a
  // map cell or 0.01 rad, the scan is matched from both, and the match without odometry is taken
  // if its residual is lower by more than this (or it passes the unverified check that the other
  // fails) and the two poses lie more than odometry_check_sigmas apart by the covariance of the
  // match with odometry (the scan tells them apart: along a corridor's axis it does not, and the
  // map made at the last pose would favour standing still; with MatcherConfig::
  // degeneracy_min_ratio only the difference along the directions the scan determines at one of
  // the two poses counts), counted odometry_overruled. 0 trusts odometry always.
  double odometry_check_margin = 0.005;
  double odometry_check_sigmas = 3.0;
  // Use odometry on a log subsampled by travel (MatcherConfig::wide_search_gap_us: the median of
  // the last five intervals above it) too. Such logs' sparse path (step prior, ensemble, lag) does
  // better without it on the CARMEN sets: intel RPE over 1 m / 10 m 0.065 / 0.131 m with it,
  // 0.059 / 0.119 m without (scripts/eval-carmen.sh intel --stages frontend --offline). A gap in
  // a scanner's stream (a sparse scan of a stream that is not subsampled) takes odometry always.
  bool subsampled_logs = false;
  double search_min_linear_m = 0.3;
  double search_min_angular_rad = 0.15;
  // Standard deviation of a prediction without odometry (the velocity of the last poses, the
  // IMU's turn) per second predicted: what a direction the scan does not determine
  // (MatcherConfig::degeneracy_min_ratio) adds to its variance per scan.
  double prediction_sigma_mps = 0.05;
  double prediction_sigma_radps = 0.02;
  // [m/s^2] The velocity of the last poses (the prediction without odometry) changes by at most
  // this times the interval per pose: a platform that is pushed, driven or carried does not gain
  // a metre a second between two scans, but a match that lands 5 cm off along a direction the
  // scan barely determines (a corridor's axis) is 4 m/s over a 13 ms interval, and the next
  // predictions would carry it on. 0: no limit. Off by default: at 2 m/s^2 it shrank the lost
  // runs of the simulator's robots without wheels but not all, and made lab-loop seed 2 worse
  // (docs/frontends.md, "Open directions without odometry"); with
  // MatcherConfig::degeneracy_hold_without_odometry it is what the hold holds to.
  double max_acceleration_mps2 = 0.0;

  template <class V>
  void visit(V& v) {
    v("source", source);
    v("odometry_max_gap_us", odometry_max_gap_us);
    v("odometry_max_extrapolation_us", odometry_max_extrapolation_us);
    v("odometry_sigma_xy_m", odometry_sigma_xy_m);
    v("odometry_sigma_xy_per_m", odometry_sigma_xy_per_m);
    v("odometry_sigma_theta_rad", odometry_sigma_theta_rad);
    v("odometry_sigma_theta_per_m", odometry_sigma_theta_per_m);
    v("odometry_sigma_theta_per_rad", odometry_sigma_theta_per_rad);
    v("search_sigmas", search_sigmas);
    v("odometry_check_margin", odometry_check_margin);
    v("odometry_check_sigmas", odometry_check_sigmas);
    v("subsampled_logs", subsampled_logs);
    v("search_min_linear_m", search_min_linear_m);
    v("search_min_angular_rad", search_min_angular_rad);
    v("prediction_sigma_mps", prediction_sigma_mps);
    v("prediction_sigma_radps", prediction_sigma_radps);
    v("max_acceleration_mps2", max_acceleration_mps2);
  }
};

// Calibration of the rig while it runs (calibration/): the horizontal scanner's yaw in the base
// frame, from the constraint that a wheeled base moves along its own x axis
// (common/extrinsic_yaw.hpp). The poses come out in the frame of the base the rig file
// meant, the map's frame the base at the first scan (initial_pose); odometry is turned into the
// frame the scans are matched in.
struct CalibrationConfig : calibration::ExtrinsicYawConfig {
  // Estimate and apply the yaw as each pose comes. Off by default: on the relations log intel it
  // made the frontend's mean translational error 0.099 m against 0.021 m without (the estimate
  // turns each new pose about the start by the estimate of the moment, so poses published while
  // it converges disagree with each other); the backend applies one estimate to the whole
  // trajectory instead (processes/backend/boresight.hpp). Never on a platform that may move
  // sideways (hand-held, omni wheels).
  bool extrinsic_yaw = false;

  template <class V>
  void visit(V& v) {
    v("extrinsic_yaw", extrinsic_yaw);
    calibration::ExtrinsicYawConfig::visit(v);
  }
};

struct FrontendConfig {
  // Which frontend runs: hector (hector/) or icp (icp/); another can take over while the graph
  // runs (frontend_node.hpp, handover).
  std::string kind = "hector";
  std::string scan_channel = channels::kScanHorizontal;
  std::string imu_channel = channels::kImu;
  std::string odometry_channel = channels::kOdometry;
  std::string pose_channel = channels::kPoseFrontend;
  Pose2Config T_base_laser;  // the horizontal scanner in the base frame
  // Pose of the base at the first scan in the map frame, T_map_base: where the trajectory starts
  // in a site's frame (a surveyed start point). The map's grid is aligned with the map frame, so
  // a sub-cell offset or a small turn here also changes how every scan falls on the cells
  // (scripts/frontend-sensitivity.sh measures what that does to a trajectory).
  Pose2Config initial_pose;
  MapConfig map;
  MatcherConfig matcher;
  DeskewConfig deskew;
  MotionPriorConfig motion_prior;
  IcpConfig icp;
  HandoverConfig handover;
  CalibrationConfig calibration;

  template <class V>
  void visit(V& v) {
    v("kind", kind);
    v("scan_channel", scan_channel);
    v("imu_channel", imu_channel);
    v("odometry_channel", odometry_channel);
    v("pose_channel", pose_channel);
    v("T_base_laser", T_base_laser);
    v("initial_pose", initial_pose);
    v("map", map);
    v("matcher", matcher);
    v("deskew", deskew);
    v("motion_prior", motion_prior);
    v("icp", icp);
    v("handover", handover);
    v("calibration", calibration);
  }
};

// The values a frontend cannot run with, named by key; nullopt when the config is usable.
std::optional<std::string> validate(const MapConfig& config);
std::optional<std::string> validate(const MatcherConfig& config);
std::optional<std::string> validate(const DeskewConfig& config);
std::optional<std::string> validate(const MotionPriorConfig& config);
std::optional<std::string> validate(const FrontendConfig& config);

}  // namespace traverse::frontend
