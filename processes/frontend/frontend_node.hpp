// Adapts LCM messages to the frontend: planar_scan_t and imu_t in, pose2d_t out (parent "map",
// child "base", one per scan). A scan waits until IMU samples cover its last point (or until a
// scan imu_wait_us later has arrived, or for good when no IMU publishes), because a log player
// delivers a sweep at its first point's time, before the IMU samples taken during the sweep.
// On a log subsampled by travel a pose comes one scan late (MatcherConfig::sparse_lag), the last
// one at shutdown (flush(true)).
#pragma once

#include <deque>
#include <functional>
#include <string>

#include "bus.hpp"
#include "frontend.hpp"
#include "traverse/imu_t.hpp"
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
  const Frontend& frontend() const { return frontend_; }

 private:
  void on_scan(const planar_scan_t& msg);
  void on_imu(const imu_t& msg);
  void publish(const FrontendResult& result);

  Bus& bus_;
  FrontendConfig config_;
  Frontend frontend_;
  CounterSink counters_;
  std::deque<Scan> pending_;
};

}  // namespace traverse::frontend
