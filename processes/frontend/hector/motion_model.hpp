// The motion of the base between scans, as cartographer's pose extrapolator: the poses the
// matcher measured go in (add_pose), and so do IMU yaw rates and wheel odometry; the pose at a
// later time comes out (extrapolate), and the heading change and velocity within a sweep for
// de-skewing it (deskew.hpp).
//   - The motion prior (../motion_prior.hpp, config motion_prior.source) says which of wheel
//     odometry and the IMU are used and how they combine: with odometry's step since the last
//     pose, the translation is odometry's and the rotation the IMU's (source both, IMU covering)
//     or odometry's.
//   - Heading change otherwise: the IMU's yaw rate integrated (yaw_integrator.hpp) when its
//     samples cover the time since the last pose, else the angular velocity of the last poses.
//   - Translation otherwise: the velocity of the last poses over the elapsed time, over at most
//     twice the last interval (after a pause it would predict an arbitrarily long step). The
//     velocity is differenced from consecutive poses and averaged exponentially over about 0.1 s
//     (poses a few milliseconds apart are noisy to difference), and changes by at most
//     MotionPriorConfig::max_acceleration_mps2 times the interval (one match off along a
//     corridor's axis is no change of speed).
//   - Sparse scans (far apart in time, see MatcherConfig::wide_search_gap_us) of a log
//     subsampled by travel (the CARMEN sets) without IMU or odometry: their times say little
//     about the motion, so the prediction is the average of the last sparse steps. Such a log
//     moves about the same distance per scan, so the average keeps predicting forward motion
//     where one step was underestimated (a corridor that does not show motion along its axis):
//     repeating the last step would repeat the stall.
// Everything derived from the poses is one State, which a frontend that takes a pose back (an
// integration undone, two_phase.hpp) restores; the IMU and odometry samples are inputs, kept.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <utility>

#include "frontend.hpp"
#include "motion_prior.hpp"
#include "recent_values.hpp"
#include "se2.hpp"
#include "yaw_integrator.hpp"

namespace traverse::frontend {

class MotionModel {
 public:
  // Before the first pose the last pose is T_map_base_initial (where the trajectory starts).
  MotionModel(const Pose2& T_map_base_initial, const Eigen::Matrix3d& R_base_imu,
              const MotionPriorConfig& prior = {});

  // Samples not after the previous one, or not finite, are refused (false).
  bool add_imu(int64_t utime, const Eigen::Vector3d& angular_velocity_imu);
  bool add_odometry(const OdometrySample& odometry);

  // A measured pose at `utime` with its covariance; `sparse`: a sparse scan's (the average step
  // of sparse scans follows it).
  void add_pose(int64_t utime, const Pose2& T_map_base, const Eigen::Matrix3d& covariance,
                bool sparse);
  // A predicted pose (nothing was measured): as add_pose, but the velocity stays as it was.
  // late: the prediction at the stamp of a scan taken earlier (taken_earlier()).
  void add_prediction(int64_t utime, const Pose2& T_map_base, const Eigen::Matrix3d& covariance,
                      bool sparse, bool late = false);

  bool initialised() const { return state_.initialised; }  // a pose was added
  const Pose2& last_pose() const { return state_.T_map_base_last; }
  int64_t last_utime() const { return state_.last_utime; }
  const Eigen::Matrix3d& last_covariance() const { return state_.covariance_last; }
  // (vx [m/s], vy [m/s], omega [rad/s]) in the base frame, from the last poses.
  const Eigen::Vector3d& velocity() const { return state_.velocity; }

  // IMU samples reach back to `from` and are recent at `to` (not older than 0.5 s), and the
  // motion prior's source includes the IMU.
  bool imu_covers(int64_t from, int64_t to) const;
  // Heading change of the base from t0 to t1 [rad] by the IMU (imu_covers() must hold).
  double imu_heading_change(int64_t t0, int64_t t1) const { return yaw_.heading_change(t0, t1); }
  // The median of the last five intervals between poses exceeds gap_us: scans come further apart
  // than any scanner's period, a log subsampled by travel.
  bool subsampled_by_travel(int64_t gap_us) const;
  // Five intervals between poses seen: subsampled_by_travel() can tell.
  bool pace_known() const { return state_.recent_intervals_us.size() == 5; }
  // A match at T_match from the prediction T_predicted lies on the path of the poses before the
  // last (within a third of a unit of one of its segments) and away from both the last pose and
  // the prediction (more than two thirds of a unit), where a unit is scale_xy in x and y and
  // scale_theta in heading: a scan taken back there and stamped late (intel's log holds such
  // scans, arriving up to a second after the next ones). Never two in a row: a second is the
  // prediction that is off (odometry that slipped), not the scan.
  bool taken_earlier(const Pose2& T_match, const Pose2& T_predicted, double scale_xy,
                     double scale_theta) const;

  // The pose at `utime` (after the last pose), see the header. use_imu: imu_covers() from the
  // last pose to utime; sparse: the scan is a sparse one.
  Pose2 extrapolate(int64_t utime, bool use_imu, bool sparse) const {
    return predict(utime, use_imu, sparse).T_map_base;
  }
  struct Prediction {
    Pose2 T_map_base;
    std::optional<OdometryStep> odometry;  // the odometry step it used, with its covariance
    OdometryMiss odometry_miss = OdometryMiss::kNone;  // why not, where the source names it
    // Of T_map_base (x [m], y [m], theta [rad], map frame): the last pose's, grown by the
    // odometry step's, or without odometry by MotionPriorConfig::prediction_sigma_* times the
    // time predicted.
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  };
  // with_odometry false: as if no odometry had come (the prediction odometry would overrule).
  Prediction predict(int64_t utime, bool use_imu, bool sparse, bool with_odometry = true) const;
  const MotionPrior& prior() const { return prior_; }

  struct State {
    bool initialised = false;
    int64_t last_utime = 0;        // [us] of the last pose
    int64_t last_interval_us = 0;  // [us] between the last two poses
    Pose2 T_map_base_last;
    Eigen::Matrix3d covariance_last = Eigen::Matrix3d::Zero();
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    // Average step per sparse scan (log of the relative pose, base frame).
    std::optional<Eigen::Vector3d> sparse_step;
    RecentValues<5> recent_intervals_us;  // between the last poses [us]
    // The poses of the last second, oldest first, with their times [us]: taken_earlier().
    std::deque<std::pair<int64_t, Pose2>> recent_path;
    bool last_late = false;  // the last pose is the prediction at a late scan's stamp
  };
  const State& state() const { return state_; }
  void restore(const State& state) { state_ = state; }

 private:
  YawIntegrator yaw_;
  MotionPrior prior_;
  State state_;
};

}  // namespace traverse::frontend
