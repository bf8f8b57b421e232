// The motion prior: what a frontend predicts a scan's pose from besides its own past poses, as a
// strategy of its own (config motion_prior.source): wheel odometry, the IMU's yaw rate, both, or
// neither. The Hector core's motion model (hector/motion_model.hpp) asks it for the step since the
// last pose; the matcher centres its searches on the prediction and, with odometry, sizes them by
// the step's covariance (hector_frontend.hpp).
//
// Combination (source both): the translation is odometry's, the rotation the IMU's where its
// samples cover the interval (a gyro does not slip; wheels do, most of all when turning), else
// odometry's. Source odometry takes both from odometry, imu only the rotation (the translation
// from the velocity of the last poses), none neither. Wherever odometry is not usable the
// prediction falls back to what the source leaves (the IMU and the poses' velocity), and the
// reason is counted:
//   - missing: no odometry yet, or none from before the last pose;
//   - gap: the samples around one of the two times are more than odometry_max_gap_us apart (the
//     odometry stopped, or messages were lost);
//   - stale: the scan comes more than odometry_max_extrapolation_us after the newest sample (the
//     odometry stopped or lags); up to that, the step is extrapolated at the newest sample's rate.
// Samples not after the previous one or not finite are refused (counted by the frontend).
//
// The step's covariance (x [m], y [m], theta [rad] in the base frame at the start) is the growth
// of the messages' accumulated pose covariance over the step, turned into that frame, plus a model
// of wheel odometry's error per metre and per radian (MotionPriorConfig), which also stands in for
// sources that report no covariance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>

#include "frontend.hpp"
#include "frontend_config.hpp"
#include "se2.hpp"

namespace traverse::frontend {

// The base's motion from t0 to t1 by wheel odometry, in the base frame at t0.
struct OdometryStep {
  Pose2 T_base0_base1;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // (x [m], y [m], theta [rad])
  bool extrapolated = false;  // t1 lies after the newest sample (within the allowance)
};

enum class OdometryMiss { kNone, kMissing, kGap, kStale };

class MotionPrior {
 public:
  explicit MotionPrior(const MotionPriorConfig& config);

  bool uses_imu() const;
  bool uses_odometry() const;

  // False (and nothing kept) for a sample not after the previous one, or not finite.
  bool add_odometry(const OdometrySample& sample);

  // The odometry step from t0 to t1 (t0 <= t1) if the samples allow it (see the header); else
  // nullopt, and `miss` (if given) says why. Always nullopt when the source leaves odometry out.
  std::optional<OdometryStep> odometry_step(int64_t t0, int64_t t1,
                                            OdometryMiss* miss = nullptr) const;

  // The search windows around a prediction by odometry: search_sigmas standard deviations of the
  // step, at least the configured minimum, at most the given windows.
  double linear_window_m(const Eigen::Matrix3d& covariance, double max_m) const;
  double angular_window_rad(const Eigen::Matrix3d& covariance, double max_rad) const;

  const MotionPriorConfig& config() const { return config_; }

 private:
  // T_odom_base at t and its accumulated covariance, if t lies within the samples (or up to the
  // extrapolation allowance after them) with no gap around it.
  struct At {
    Pose2 T_odom_base;
    Eigen::Matrix3d covariance;
    bool extrapolated = false;
  };
  std::optional<At> at(int64_t t, OdometryMiss* miss) const;

  MotionPriorConfig config_;
  std::deque<OdometrySample> samples_;
};

}  // namespace traverse::frontend
