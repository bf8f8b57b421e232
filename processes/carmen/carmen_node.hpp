// Turns a CARMEN log's records into Traverse messages: each scan becomes a planar_scan_t on
// channels::kScanHorizontal (frame "laser_horizontal") and its logged pose a pose2d_t on
// channels::kPoseReference (T_world_base); the odometry becomes odometry_t on channels::kOdometry
// (T_odom_base, parent frame "odom", child "base").
//
// Frames: CARMEN logs the pose of the laser. We take the base frame to be the horizontal laser's
// frame (T_base_laser = identity), so the logged pose is T_world_base; the Radish logs used here
// state a front-laser offset of 0 (intel, aces, csail) or 4 cm (freiburg), which this ignores.
// The logged pose is a reference only in a corrected log; in a raw log (the full-rate logs of the
// relations benchmark) it is the odometry itself.
// Time: CARMEN stamps a scan once, so utime_first = utime_last = its time (log_reader.hpp);
// consumers must not read a sweep duration into it.
// Odometry: the ODOM lines (or, without any, the laser lines' odometry fields) as a chain of the
// log's own increments with the configured noise model (odometry.hpp), one message per ODOM line
// in time order. On a log whose stamps carry no time, one message per scan at the scan's time,
// from the last odometry read before it. A velocity is given where the log states one (ODOM tv
// and rv when any is non-zero, ROBOTLASER1); otherwise velocity and its covariance are all zero
// (unknown).
#pragma once

#include <Eigen/Core>
#include <deque>
#include <functional>
#include <optional>
#include <string>

#include "carmen_config.hpp"
#include "carmen_log.hpp"
#include "log_reader.hpp"
#include "odometry.hpp"
#include "publisher.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::carmen {

inline constexpr const char* kLaserFrame = "laser_horizontal";
inline constexpr const char* kOdometryFrame = "odom";

// A scan with more than cfg.max_beams beams is thinned to every k-th beam, k the smallest that
// fits. Its range_max stays below the no-return code, if the scan has one.
planar_scan_t to_scan_message(const Scan& scan, const CarmenConfig& cfg);
pose2d_t to_reference_pose(const Scan& scan);
// `velocity` (forward [m/s], left [m/s], turn [rad/s]) when the log states it.
odometry_t to_odometry_message(int64_t utime, const OdometryChain& chain,
                               const std::optional<Eigen::Vector3d>& velocity,
                               const OdometryNoise& noise);

enum class OdometrySource { kOdom, kLaser, kNone };
const char* odometry_source_name(OdometrySource source);  // "odom", "laser", "none"
// The configured source (auto, odom, laser, none) for a surveyed log; auto picks odom when the
// log has ODOM lines that are measurements, else laser when it has scans.
OdometrySource choose_odometry_source(const std::string& configured, const Summary& survey);

// Publishes every record of a log, in time order across channels: a scan at time t goes out after
// the odometry up to t, odometry read before a scan but stamped after it waits for it, and
// odometry stamped before a scan already published is dropped (counted). Each channel's times
// strictly increase, and so do the times of the whole output.
class Driver {
 public:
  // `pace(utime)` is called before each message is published (live: waits for its time).
  Driver(Publisher& out, const CarmenConfig& cfg, OdometrySource source, const Summary& survey,
         std::function<void(int64_t utime)> pace = {});
  void publish(const Record& record);
  // End of the log: what still waits.
  void finish();

  int64_t scans() const { return scans_; }
  int64_t odometry() const { return odometry_; }
  int64_t scans_thinned() const { return scans_thinned_; }  // over cfg.max_beams
  // Odometry stamped no later than a scan already published (a log whose odometry and scan
  // stamps disagree, e.g. the Radish intel log's ODOM lines, up to a second off).
  int64_t odometry_behind_scans() const { return odometry_behind_scans_; }

 private:
  void on_scan(const Scan& scan);
  void on_odometry(const OdometryReading& reading);
  void queue_odometry(int64_t utime, const std::optional<Eigen::Vector3d>& velocity);
  void flush_odometry(int64_t up_to_utime);

  Publisher& out_;
  const CarmenConfig& cfg_;
  OdometrySource source_;
  bool timeless_;         // the log's stamps carry no time: odometry per scan
  bool velocity_in_log_;  // ODOM lines state velocity
  std::function<void(int64_t)> pace_;
  OdometryChain chain_;
  std::deque<odometry_t> pending_;  // increasing times, all after the last scan published
  std::optional<int64_t> last_scan_utime_, last_odometry_utime_;
  int64_t scans_ = 0, odometry_ = 0, scans_thinned_ = 0, odometry_behind_scans_ = 0;
};

}  // namespace traverse::carmen
