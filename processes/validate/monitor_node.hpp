// The monitor's node: listens to every channel of the bus, feeds each message to the same stream
// checks traverse-validate runs on logs (event time = receive time), and follows every process
// through the process_status_t it publishes on STATUS_<NAME>.
#pragma once

#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <optional>
#include <string>

#include "bus.hpp"
#include "process_tracker.hpp"
#include "run_summary.hpp"
#include "stream_analyzer.hpp"

namespace traverse {

namespace validate {

// The verdict's thresholds: a run is ok only when every figure is within them (the defaults
// allow no loss at all; a clean run on one host loses nothing).
struct MonitorConfig {
  double status_timeout_s = 3.0;  // [s] a process whose status is not heard for longer is silent
  double max_status_gap_s = 3.0;  // [s] longest interval between two statuses of a process
  int64_t max_missed = 0;         // [messages] a process reports skipped (sequence numbers)
  int64_t max_out_of_order = 0;   // [messages] a process dropped as stamped before the last one
  int64_t max_queue_dropped = 0;  // [messages] a process's receive queue dropped
  int64_t max_rejected = 0;       // [messages] a process rejected or dropped as stamp outliers
  int64_t max_seq_gaps = 0;       // [messages] the monitor itself missed on a channel: above
                                  // it a note (its own reception), not a failed run

  template <class V>
  void visit(V& v) {
    v("status_timeout_s", status_timeout_s);
    v("max_status_gap_s", max_status_gap_s);
    v("max_missed", max_missed);
    v("max_out_of_order", max_out_of_order);
    v("max_queue_dropped", max_queue_dropped);
    v("max_rejected", max_rejected);
    v("max_seq_gaps", max_seq_gaps);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const MonitorConfig& config);

}  // namespace validate
using validate::MonitorConfig;

class MonitorNode {
 public:
  // `self`: the monitor's own process name (never judged silent: it is the one judging).
  // `live`: statuses arrive in real time, so gaps and silence mean something (not on a replay).
  MonitorNode(Bus& bus, const MonitorConfig& cfg, std::string self = "monitor", bool live = true);
  ~MonitorNode();
  MonitorNode(const MonitorNode&) = delete;
  MonitorNode& operator=(const MonitorNode&) = delete;

  // Everything heard so far, judged at `now_utime` [us] (local clock).
  validate::RunSummary summary(int64_t now_utime) const;

  int64_t events() const { return analyzer_.events(); }

 private:
  void on_message(const std::string& channel, const uint8_t* data, int size, int64_t recv_utime);
  validate::Thresholds thresholds() const;

  Bus& bus_;
  MonitorConfig cfg_;
  std::string self_;
  bool live_;
  Bus::Handle subscription_ = nullptr;
  validate::StreamAnalyzer analyzer_;
  validate::ProcessTracker tracker_;
  int64_t start_utime_ = 0;
  int64_t status_decode_failures_ = 0;
};

}  // namespace traverse
