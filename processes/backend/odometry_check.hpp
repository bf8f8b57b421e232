// Wheel odometry as a check on the frontend's motion between key poses (issue: the backend uses
// odometry where scan matching is weak).
//
// A scan-to-map frontend that loses track (a featureless corridor, a turn on the spot in
// clutter) publishes a step that is wrong by metres or tens of degrees, often with a covariance
// as small as any other. Wheel odometry errs by a few per cent of the travel, but never that
// much over a third of a second. So each frontend step between two key poses is compared with
// the odometry's motion over the same interval. When the two disagree beyond the odometry's
// error model (chi-square gate, 3 degrees of freedom), the scans decide (backend.cpp): the link
// is matched around both steps, and if the scans agree better with the odometry's, it takes the
// frontend's place in the pose graph (with the odometry's covariance) and as the link's guess.
// Odometry can slip, and the subsampled CARMEN logs' odometry restarts at every scan: taken
// unchecked it replaced good frontend steps there (RPE over 10 m on intel 0.11 -> 0.82 m).
// Without odometry messages nothing changes.
//
// Odometry poses T_odom_base are kept for a bounded time and interpolated at the key poses'
// times; only differences between two of them are used (the odom frame drifts without bound).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "se2.hpp"

namespace traverse::backend {

struct OdometryCheckConfig {
  bool enabled = true;  // false: odometry messages are ignored
  // The odometry's error over a motion, as independent standard deviations that grow with the
  // travel d [m] and the turn |dtheta| [rad]: sigma_xy = min_sigma_xy_m + sigma_xy_per_m * d,
  // sigma_theta = min_sigma_theta_rad + sigma_theta_per_m * d + sigma_theta_per_rad * |dtheta|.
  double min_sigma_xy_m = 0.02;         // [m]
  double sigma_xy_per_m = 0.1;          // [m/m]
  double min_sigma_theta_rad = 0.02;    // [rad]
  double sigma_theta_per_m = 0.05;      // [rad/m]
  double sigma_theta_per_rad = 0.1;     // [rad/rad]
  double max_frontend_chi2 = 16.3;      // frontend step vs odometry beyond this: rejected
  int64_t max_reading_gap_us = 500000;  // [us] a key pose's time this far from any reading: none
  int64_t keep_us = 120'000'000;        // [us] readings kept this long behind the newest
  // A reading that implies a speed or a turn rate above these since the one before says the
  // stream's stamps do not follow the motion (Kummerle's intel: bursts of readings stamped within
  // a millisecond after half a second without any, and two runs of readings interleaved, 0.2 m
  // apart; 16,611 of its 26,915 readings imply over 3 m/s, none of aces' or fr079's). No step
  // whose readings lie within max_reading_gap_us of such a reading is checked: its odometry step
  // says nothing about the motion.
  double max_speed_mps = 3.0;        // [m/s]
  double max_turn_rate_radps = 6.0;  // [rad/s]

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("min_sigma_xy_m", min_sigma_xy_m);
    v("sigma_xy_per_m", sigma_xy_per_m);
    v("min_sigma_theta_rad", min_sigma_theta_rad);
    v("sigma_theta_per_m", sigma_theta_per_m);
    v("sigma_theta_per_rad", sigma_theta_per_rad);
    v("max_frontend_chi2", max_frontend_chi2);
    v("max_reading_gap_us", max_reading_gap_us);
    v("keep_us", keep_us);
    v("max_speed_mps", max_speed_mps);
    v("max_turn_rate_radps", max_turn_rate_radps);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const OdometryCheckConfig& config);

struct OdometryCounters {
  long readings = 0;               // odometry messages taken
  long readings_out_of_order = 0;  // ... dropped: not later than the one before
  long readings_implausible = 0;   // ... kept, but over max_speed_mps or max_turn_rate_radps
  long steps_implausible = 0;      // key steps not checked: an implausible reading nearby
  long steps_checked = 0;          // key steps with odometry at both ends
  long steps_contradicted = 0;     // ... where the frontend's step failed the gate
};

// The odometry's verdict on one frontend step between key poses.
struct OdometryStep {
  Pose2 motion;                    // the odometry's motion from the first to the second pose
  Eigen::Matrix3d covariance;      // its covariance in the first pose's frame: m^2, m rad, rad^2
  double frontend_chi2 = 0.0;      // the frontend's step against it
  bool frontend_rejected = false;  // frontend_chi2 over the gate
};

// e^T S^-1 e of two motions' difference e (x [m], y [m], wrapped theta [rad]) under covariance S.
double step_chi2(const Pose2& a, const Pose2& b, const Eigen::Matrix3d& S);

// Whether the scans side with the odometry where it contradicts the frontend's step: the link
// matched around the odometry's step (`match`, with its covariance, both in the frame of the
// step's first pose) must score better than the one around the frontend's
// (`match_raw_response > frontend_match_raw_response`), and land within the gate of the
// odometry's step and beyond the gate of the frontend's (each with its own covariance added to
// the match's). A better score alone is no verdict: when both searches end on the same pose (the
// scans fit the frontend's step, the odometry's readings came in a burst), the scores differ by
// noise; on Kummerle's intel such a replaced step turned the rest of the run by 1.5 degrees.
bool scans_side_with_odometry(const OdometryStep& odometry, const Pose2& frontend_motion,
                              const Eigen::Matrix3d& frontend_covariance, const Pose2& match,
                              const Eigen::Matrix3d& match_covariance, double match_raw_response,
                              double frontend_match_raw_response, double gate_chi2);

class OdometryCheck {
 public:
  // The config must pass validate().
  explicit OdometryCheck(OdometryCheckConfig config) : config_(config) {}

  // An odometry reading (T_odom_base at utime); readings not later than the last are dropped.
  void add(int64_t utime, const Pose2& T_odom_base);
  // The odometry's motion from time a to time b, compared with the frontend's (nullopt: no
  // odometry around either time, or disabled). `frontend_covariance`: the frontend step's, in
  // the frame of a (zero: the odometry's model alone decides).
  std::optional<OdometryStep> check(int64_t a_utime, int64_t b_utime, const Pose2& frontend_motion,
                                    const Eigen::Matrix3d& frontend_covariance);
  // The same comparison, not counted: a second look over steps already checked.
  std::optional<OdometryStep> compare(int64_t a_utime, int64_t b_utime,
                                      const Pose2& frontend_motion,
                                      const Eigen::Matrix3d& frontend_covariance) const;

  const OdometryCounters& counters() const { return counters_; }

 private:
  std::optional<Pose2> at(int64_t utime) const;
  // An implausible reading within max_reading_gap_us of the interval [a, b].
  bool implausible_near(int64_t a_utime, int64_t b_utime) const;
  // The odometry's step from pose a to pose b (its error model) against the frontend's.
  OdometryStep judge(const Pose2& a, const Pose2& b, const Pose2& frontend_motion,
                     const Eigen::Matrix3d& frontend_covariance) const;

  OdometryCheckConfig config_;
  OdometryCounters counters_;
  std::deque<std::pair<int64_t, Pose2>> readings_;
  std::deque<int64_t> implausible_;  // times of implausible readings, kept as long as readings
};

}  // namespace traverse::backend
