// The frontend's per-scan pipeline (seed 000 section 2, Hector SLAM section IV):
//   1. keep the valid readings of the scan (finite, inside the scanner's and the config's range);
//   2. predict the pose at the scan's last point by constant velocity (heading change from the
//      IMU when one is publishing); for sparse scans (more than matcher.wide_search_gap_us after
//      the last pose, or in a stream whose recent scans were: a log subsampled by travel) by
//      the average step per scan;
//   3. undo the motion during the sweep: every point is moved into the base frame at the scan's
//      last point with the heading change at its own time (IMU yaw rate, or the constant
//      angular velocity without IMU) and, optionally, the constant-velocity translation;
//   4. match the points against the map pyramid, coarse to fine, from the prediction (sparse
//      scans: from the best pose of a wide correlative search around it, which on a log
//      subsampled by travel also weighs the step's shape: MatcherConfig::sparse_step_*);
//   5. update the map when the pose moved or turned past a threshold since the last update.
// Sparse scans go through this pipeline in several frontends at once (an ensemble, see
// MatcherConfig::sparse_ensemble_members), each with its own map on a grid offset by a fraction
// of a cell; the published pose is the previous one times the step most of them agree on. On a
// log subsampled by travel each frontend runs one scan behind (MatcherConfig::sparse_lag): a
// scan's map update is journaled until the next scan has been matched, and its pose may then
// move to where the pair of steps around it says (its map update moving with it).
// A scan with too few valid points, or whose match on a scanner's stream lands far from the
// prediction with a poor fit, gets the predicted pose (flagged); a scan whose time does not
// advance, or whose last point is before its first, is dropped. Each case is counted.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "frontend_config.hpp"
#include "planar_scan.hpp"
#include "scan_matcher.hpp"
#include "se2.hpp"
#include "yaw_integrator.hpp"

namespace traverse::frontend {

using Scan = PlanarScan;

enum class ScanStatus {
  kMatched,    // pose measured by matching (the first scan: its pose is the config's initial_pose)
  kPredicted,  // pose predicted from motion: too few valid points, or an unverified match
  kDropped,    // time does not advance or is inconsistent: no pose
  kHeld,       // no pose yet: a log subsampled by travel is one scan behind (MatcherConfig::
               // sparse_lag); the pose comes with the next scan's result or from finish()
};

struct FrontendResult {
  ScanStatus status = ScanStatus::kDropped;
  bool has_pose() const {
    return status == ScanStatus::kMatched || status == ScanStatus::kPredicted;
  }
  int64_t utime = 0;  // [us] time the pose is valid at: the scan's last point
  Pose2 T_map_base;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // (x [m], y [m], theta [rad])
  Pose2 T_map_base_predicted;  // the motion prediction the match started from
  bool map_updated = false;
  bool imu_used = false;
  int valid_points = 0;
  int matched_points = 0;
  int iterations = 0;
  double residual_rms = 0.0;  // [unitless] RMS of 1 - M at the result
  bool searched = false;      // the matcher needed its recovery search
  bool sparse = false;        // matched as a sparse scan (wide search)
  // Sparse-scan ensemble (matcher.sparse_ensemble_members): members whose step agrees with the
  // published one, of how many voted; 0 of 0 without an ensemble.
  int ensemble_agreeing = 0, ensemble_voting = 0;
};

struct FrontendCounters {
  int64_t scans_received = 0;
  int64_t scans_matched = 0;
  int64_t scans_predicted = 0;     // too few valid points
  int64_t scans_unverified = 0;    // match far from the prediction with a poor fit: predicted
  int64_t scans_searched = 0;      // matches that needed the recovery search
  int64_t scans_dropped_time = 0;  // time going backwards or utime_last < utime_first
  int64_t readings_invalid = 0;    // NaN, zero or out-of-range readings ignored
  int64_t map_updates = 0;
  int64_t map_tiles_evicted = 0;
  int64_t imu_samples = 0;
  int64_t imu_dropped_time = 0;  // IMU samples not after the previous one
  int64_t steps_disputed = 0;    // sparse ensemble: steps on which not every member agreed
  int64_t steps_outvoted = 0;    // ... on which this frontend's own step lost the vote
  int64_t scans_revised = 0;     // sparse lag: poses moved once the next scan was matched
};

// The vote of a sparse-scan ensemble on one step (each member's step from its last pose to its
// new one, in its own map): the step with the most steps within 0.15 m and 0.05 rad of it (on a
// tie the earliest), how many those are, and the second moment of all steps about it (x, y in
// the frame `R_map_last` turns them into, [m^2, rad^2]).
struct StepVote {
  std::size_t chosen = 0;
  int support = 0;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
};
StepVote vote_on_steps(const std::vector<Pose2>& steps, const Eigen::Matrix2d& R_map_last);
// Whether two steps (or poses) agree: within 0.15 m and 0.05 rad.
bool poses_agree(const Pose2& a, const Pose2& b);

// The last N values of a stream (a ring): how many are held, and their percentiles.
template <std::size_t N>
class RecentValues {
 public:
  void add(double value) { values_[count_++ % N] = value; }
  std::size_t size() const { return std::min(count_, N); }
  // The (size() * percent / 100)-th smallest of those held, counting from 0; size() > 0.
  double percentile(std::size_t percent) const {
    std::array<double, N> v = values_;
    const std::size_t n = size(), k = std::min(n - 1, n * percent / 100);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k),
                     v.begin() + static_cast<std::ptrdiff_t>(n));
    return v[k];
  }

 private:
  std::array<double, N> values_{};
  std::size_t count_ = 0;
};

class Frontend {
 public:
  explicit Frontend(const FrontendConfig& config);

  // Adds an IMU sample: angular velocity [rad/s] in the IMU frame.
  void add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu);
  // Time of the newest IMU sample, if any arrived.
  std::optional<int64_t> last_imu_utime() const;

  // One pose per scan (status kDropped: none). With a sparse-scan ensemble, the pose is the
  // previous one times the step most members agree on (see MatcherConfig). On a log subsampled
  // by travel (with MatcherConfig::sparse_lag) the frontend runs one scan behind from the scan
  // where it notices: the result is the previous scan's pose (its utime says which), the first
  // such call returns kHeld, and finish() gives the last scan's pose at the end of the stream.
  FrontendResult process(const Scan& scan);
  // The pose of the scan still held by the lag, if any (at the end of the stream).
  std::optional<FrontendResult> finish();

  const FrontendCounters& counters() const { return counters_; }
  const MapPyramid& map() const { return map_; }
  // Bytes held by this frontend's map and, while a sparse-scan ensemble runs, its members' maps.
  std::size_t map_memory_bytes() const;
  const FrontendConfig& config() const { return config_; }

 private:
  // A held scan (sparse lag): its result from its own match, its points (base frame, deskewed;
  // all valid ones for the map, subsampled for matching) and the pose its step starts from.
  struct Held {
    FrontendResult result;
    std::vector<Eigen::Vector2d> points, points_matched;
    Pose2 T_before;
    Pose2 T_last_update_before;  // the pose of the map's last update before this scan's
  };
  // The pipeline of one frontend: its own pose in its own map (one scan behind when lagging).
  FrontendResult process_own(const Scan& scan);
  // Matching and motion state of one scan, without the map update; the scan's valid points stay
  // in points_buffer_, subsampled in matched_buffer_.
  FrontendResult measure(const Scan& scan, bool& by_travel);
  // Settles the held scan's pose given the next scan's own result (none at the end), moving its
  // journaled map update if the pose moves, and returns it.
  FrontendResult settle(Held& held, const FrontendResult* next);
  // The map update of a matched scan at its pose, when due (always for the first).
  void add_to_map(FrontendResult& result, const std::vector<Eigen::Vector2d>& points);
  // The lag's score of the held scan at T (see MatcherConfig::sparse_lag): mean evidence per
  // point minus the step priors of the steps into T and from T to the next scan's pose.
  double lag_score(const Held& held, const Pose2& T, const Pose2& T_next) const;
  // Finishes this frontend's own held scan (status kDropped: none held).
  FrontendResult finish_own();
  // Runs `own` (one frontend's step: process_own, finish_own) on this frontend and each member of
  // the ensemble, and, with an ensemble configured, votes on the result.
  FrontendResult run_and_vote(const std::function<FrontendResult(Frontend&)>& own);
  // Gives `result` the pose of a match and its figures (iterations add up).
  static void take_match(FrontendResult& result, const MatchResult& m);
  // Votes on the step from the last pose (`last`: the one this frontend, then each member, last
  // gave before this result) among this frontend and the ensemble's members; `result` (this
  // frontend's own) becomes the published pose.
  void vote(FrontendResult& result, const std::vector<FrontendResult>& member_results,
            const std::vector<Pose2>& last);
  // Valid readings as points in the base frame with their times; counts invalid ones.
  void valid_points(const Scan& scan, std::vector<Eigen::Vector2d>& points_base,
                    std::vector<int64_t>& utimes);
  bool imu_active(const Scan& scan) const;
  Pose2 predict(int64_t utime, bool use_imu, bool sparse_scan) const;
  void deskew(std::vector<Eigen::Vector2d>& points_base, const std::vector<int64_t>& utimes,
              int64_t utime_ref, bool use_imu) const;
  std::vector<Eigen::Vector2d> subsample(const std::vector<Eigen::Vector2d>& points) const;
  void update_motion(const Pose2& T_map_base, int64_t utime, bool sparse_scan);
  bool map_update_due(const Pose2& T_map_base) const;
  Pose2 initial_pose() const;  // the config's initial_pose
  // Gives `result` the predicted pose and a covariance grown by the prior's from the last one.
  void take_prediction(FrontendResult& result, const Pose2& T_pred, bool sparse_scan);
  // Whether the stream's recent scans came further apart than wide_search_gap_us (their median):
  // a log subsampled by travel, not a pause in a scanner's stream. Such a stream's scans are all
  // matched as sparse scans (see the config's wide_search_gap_us), with the step prior.
  bool subsampled_by_travel() const;

  FrontendConfig config_;
  Pose2 T_base_laser_;
  MapPyramid map_;
  YawIntegrator yaw_;
  FrontendCounters counters_;

  bool initialised_ = false;
  int64_t last_utime_ = 0;        // [us] of the last pose
  int64_t last_interval_us_ = 0;  // [us] between the last two poses
  Pose2 T_map_base_last_;
  Eigen::Vector3d velocity_ = Eigen::Vector3d::Zero();  // (vx [m/s], vy [m/s], omega [rad/s]) base
  Pose2 T_map_base_last_update_;
  // Average step per scan (log of the relative pose, base frame) of sparse scans.
  Eigen::Vector3d sparse_step_ = Eigen::Vector3d::Zero();
  bool have_sparse_step_ = false;
  Eigen::Matrix3d covariance_last_ = Eigen::Matrix3d::Zero();
  // The intervals between the last kRecentIntervals poses [us].
  static constexpr std::size_t kRecentIntervals = 5;
  RecentValues<kRecentIntervals> recent_intervals_us_;

  // Sparse lag: whether this stream runs one scan behind, the scan held, the pose last emitted
  // (own map frame), and the lengths of the last settled steps [m].
  bool lagging_ = false;
  std::optional<Held> held_;
  Pose2 T_emitted_last_;
  static constexpr std::size_t kRecentSteps = 30;
  RecentValues<kRecentSteps> recent_steps_m_;

  // Sparse-scan ensemble: the other members (each a frontend of one, its grid offset); the last
  // published pose; how many scans in a row were not sparse (three drop the members: a scanner's
  // stream).
  std::vector<std::unique_ptr<Frontend>> members_;
  Pose2 T_published_last_;
  int dense_in_a_row_ = 0;

  // Reused between scans: beam directions of the last scan geometry, and point buffers.
  std::size_t beam_n_ = 0;
  double beam_angle_first_ = 0.0, beam_angle_step_ = 0.0;
  std::vector<Eigen::Vector2d> beam_directions_;
  std::vector<Eigen::Vector2d> points_buffer_, matched_buffer_;
  std::vector<int64_t> utimes_buffer_;
};

}  // namespace traverse::frontend
