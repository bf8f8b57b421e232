// The Hector frontend (seed 000 section 2, Hector SLAM section IV), a two-phase frontend
// (two_phase.hpp). Measuring a scan:
//   1. keep the valid readings (finite, inside the scanner's and the config's range; too few:
//      the pose is predicted, flagged);
//   2. predict the pose at the scan's last point (motion_model.hpp: IMU, odometry as the motion
//      prior combines them (../motion_prior.hpp), the velocity of the last poses, or the average
//      step of a sparse log); with odometry, the searches below are centred on the prediction and
//      sized by the odometry step's covariance, and the recovery search leaves the last pose out;
//   3. undo the motion during the sweep (deskew.hpp), and on a scanner's stream leave out the
//      points that lie where the map has seen through (moved_points.hpp: people, mixed pixels);
//   4. match the points against the map pyramid, coarse to fine, from the prediction
//      (scan_matcher.hpp); sparse scans, those more than matcher.wide_search_gap_us after the
//      last pose or of a stream whose recent scans were (a log subsampled by travel), from the
//      best pose of a wide correlative search around it (grid_search.hpp), which on a log
//      subsampled by travel also weighs the step's shape (step_prior.hpp);
//   5. a match on a scanner's stream that lands far from the prediction with a poor fit is not
//      trusted: the pose is the prediction, flagged, and the scan stays out of the map; one that
//      lands, with odometry, far behind the prediction and the last pose on the path before it
//      was taken back there and stamped late: its pose is the match, the scan stays out of the
//      map and the motion goes on from the prediction;
//   6. directions of the pose the scan does not determine (a bare corridor's axis) keep the
//      prediction, and its covariance (degeneracy.hpp).
// Integrating it: the pose goes into the motion model, and the scan into the map when the pose
// moved or turned past a threshold since the last update. A scan whose time does not advance, or
// whose last point is before its first, is dropped. Each case is counted.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "degeneracy.hpp"
#include "frontend_config.hpp"
#include "map_pyramid.hpp"
#include "motion_model.hpp"
#include "open_direction_hold.hpp"
#include "scan_matcher.hpp"
#include "scan_points.hpp"
#include "two_phase.hpp"

namespace traverse::frontend {

class HectorFrontend final : public TwoPhaseFrontend {
 public:
  // The config must pass validate(); the trajectory starts at config.initial_pose.
  explicit HectorFrontend(const FrontendConfig& config);

  bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu) override;
  bool add_odometry(const OdometrySample& odometry) override;
  Measurement measure(const Scan& scan) override;
  void integrate(Measurement& measurement) override;
  Measurement rematch(const Measurement& measurement, const SearchArea& area) const override;
  double evidence(const Measurement& measurement, const Pose2& T_map_base) const override;
  Pose2 last_pose() const override { return motion_.last_pose(); }
  void begin_tentative() override;
  void rollback() override;
  void commit() override;
  std::size_t map_bytes() const override { return map_.memory_bytes(); }
  void report(const CounterSink& sink) const override;

  const MapPyramid& map() const { return map_; }

 private:
  struct Counters {
    int64_t scans_received = 0;
    int64_t scans_matched = 0;
    int64_t scans_predicted = 0;     // too few valid points
    int64_t scans_unverified = 0;    // match far from the prediction with a poor fit: predicted
    int64_t scans_late = 0;          // match on the path before the last pose: stamped late
    int64_t scans_searched = 0;      // matches that needed a correlative search
    int64_t scans_degenerate = 0;    // matches with a direction held at the prediction
    int64_t scans_dropped_time = 0;  // time going backwards or utime_last < utime_first
    int64_t readings_invalid = 0;    // NaN, zero or out-of-range readings ignored
    int64_t points_moved = 0;        // points where the map saw through (moved_points.hpp)
    int64_t map_updates = 0;
    int64_t map_tiles_evicted = 0;
    int64_t imu_samples = 0;
    int64_t imu_dropped = 0;  // IMU samples not after the previous one, or not finite
    int64_t odometry_samples = 0;
    int64_t odometry_dropped = 0;  // not after the previous sample, or not finite
    // Scans predicted with odometry's step (of which extrapolated past the newest sample), and
    // scans of a stream with odometry predicted without it, by reason (motion_prior.hpp).
    int64_t odometry_predictions = 0;
    int64_t odometry_extrapolated = 0;
    int64_t odometry_overruled = 0;  // the match without odometry's step fit clearly better
    int64_t odometry_missing = 0;
    int64_t odometry_gap = 0;
    int64_t odometry_stale = 0;
  };
  // What an integration changes besides the map's cells: undone with them.
  struct Integrated {
    MotionModel::State motion;
    std::optional<Pose2> T_map_base_last_update;  // the pose of the map's last update
    int64_t map_updates = 0;
  };

  // The measurement's pose predicted (status kPredicted), its covariance the last one's grown by
  // the motion prior's.
  void take_prediction(Measurement& m, const Pose2& T_predicted) const;
  bool map_update_due(const Pose2& T_map_base) const;
  // A match from one prediction; unverified: see measure() (a scanner's stream only).
  struct Attempt {
    MotionModel::Prediction prediction;
    MatchResult match;
    bool unverified = false;
  };
  // coarse_check: the scan may take the matcher's coarse-cell check
  // (MatcherConfig::coarse_check_m).
  Attempt match_from(const Measurement& m, const MotionModel::Prediction& prediction,
                     bool coarse_check) const;
  // Drops the points the map has seen through at the predicted pose (moved_points.hpp,
  // MatcherConfig::moved_max_probability), unless that is most of them.
  void drop_moved(std::vector<Eigen::Vector2d>& points_base, const Pose2& T_map_base_predicted);
  // The result's pose and covariance with the directions the scan does not determine held at
  // the prediction (degeneracy.hpp, MatcherConfig::degeneracy_min_ratio); points_matched: the
  // points the match was made with.
  void hold_degenerate(FrontendResult& r, const MatchResult& match,
                       const std::vector<Eigen::Vector2d>& points_matched,
                       const MotionModel::Prediction& prediction);
  // a and b lie more than a map cell or 0.01 rad apart (worth matching from both).
  bool differ(const Pose2& a, const Pose2& b) const;
  // a fits better than b: verified where b is not, else a residual lower by more than margin.
  static bool better(const Attempt& a, const Attempt& b, double margin);
  // a's pose lies more than `sigmas` standard deviations of b's covariance from b's, counting
  // only the difference along the directions `determined` projects onto (map frame).
  static bool apart(const Attempt& a, const Attempt& b, const Eigen::Matrix3d& determined,
                    double sigmas);
  // The degenerate directions of a match's information (degeneracy.hpp), and the projector onto
  // the directions the match determines (the identity with MatcherConfig::degeneracy_min_ratio
  // off, or when it determines none: its points fell where the map knows nothing).
  Degeneracy degeneracy(const Eigen::Matrix3d& information,
                        const std::vector<Eigen::Vector2d>& points_matched) const;
  Eigen::Matrix3d determined(const MatchResult& match,
                             const std::vector<Eigen::Vector2d>& points_matched) const;
  void count_odometry(const MotionModel::Prediction& prediction);
  // The matcher's config for a prediction: the searches' windows sized by its odometry step;
  // normal projection only with odometry.
  MatcherConfig matcher_for(const MotionModel::Prediction& prediction) const;

  FrontendConfig config_;
  Pose2 T_initial_;
  ScanPointMaker scan_points_;
  MotionModel motion_;
  MapPyramid map_;
  std::optional<Pose2> T_map_base_last_update_;
  std::optional<Integrated> before_tentative_;
  OpenDirectionHold open_hold_;
  Counters counters_;
};

}  // namespace traverse::frontend
