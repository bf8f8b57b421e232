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

struct MonitorConfig {
  double status_timeout_s = 3.0;  // [s] a process whose status is not heard for longer is silent

  template <class V>
  void visit(V& v) {
    v("status_timeout_s", status_timeout_s);
  }
};

// The first value out of range, named by its key; nullopt when the config is valid.
std::optional<std::string> validate(const MonitorConfig& config);

}  // namespace validate
using validate::MonitorConfig;

class MonitorNode {
 public:
  MonitorNode(Bus& bus, const MonitorConfig& cfg);
  ~MonitorNode();
  MonitorNode(const MonitorNode&) = delete;
  MonitorNode& operator=(const MonitorNode&) = delete;

  // Everything heard so far, judged at `now_utime` [us] (local clock).
  validate::RunSummary summary(int64_t now_utime) const;

  int64_t events() const { return analyzer_.events(); }

 private:
  void on_message(const std::string& channel, const uint8_t* data, int size, int64_t recv_utime);

  Bus& bus_;
  Bus::Handle subscription_ = nullptr;
  validate::StreamAnalyzer analyzer_;
  validate::ProcessTracker tracker_;
  int64_t start_utime_ = 0;
  int64_t status_decode_failures_ = 0;
};

}  // namespace traverse
