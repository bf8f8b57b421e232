// Adapts LCM messages to the frontend (frontend.hpp, made by make_frontend()): planar_scan_t,
// imu_t and odometry_t in, pose2d_t out (parent "map", child "base", one per scan, FLAG_PREDICTED
// when the frontend says kPredicted), the frontend's counters into the process status. A scan waits
// until IMU samples cover its last point (or until a scan imu_wait_us later has arrived, or for
// good when no IMU publishes), because a log player delivers a sweep at its first point's time,
// before the IMU samples taken during the sweep; likewise for odometry, once any has come (its
// messages may trail the scan). A frontend may give a pose a scan late (on a log subsampled by
// travel: MatcherConfig:: sparse_lag), the last one at shutdown (flush(true)).
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "bus.hpp"
#include "frontend.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"

namespace traverse::frontend {

class FrontendNode {
 public:
  using CounterSink = std::function<void(const std::string& name, double value)>;
  FrontendNode(Bus& bus, const FrontendConfig& config, CounterSink counters = {});

  // Processes every scan that is ready; all waiting scans, and the one the lag holds, if `all`
  // (at shutdown).
  void flush(bool all = false);
  // Copies the frontend's counters to the sink (status counters of the process).
  void report_counters();
  const Frontend& frontend() const { return *frontend_; }

 private:
  void on_scan(const planar_scan_t& msg);
  void on_imu(const imu_t& msg);
  void on_odometry(const odometry_t& msg);
  void publish(const FrontendResult& result);

  Bus& bus_;
  FrontendConfig config_;
  std::unique_ptr<Frontend> frontend_;
  CounterSink counters_;
  std::deque<Scan> pending_;
  std::optional<int64_t> last_imu_utime_;       // [us] of the newest IMU sample the frontend took
  std::optional<int64_t> last_odometry_utime_;  // [us] of the newest odometry sample it took
};

}  // namespace traverse::frontend
