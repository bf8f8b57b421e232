// Keeps track of the processes of a running graph from the status each publishes once a second:
// when each was last heard, what it reports (CPU time, memory, the input problems it counted),
// and which went silent -- a process that stops publishing status without saying "stopping" has
// died or hung.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "status_report.hpp"

namespace traverse::validate {

// One status message in plain terms (common/status_report.hpp: report_of converts
// process_status_t to it).
using ProcessReport = StatusReport;

struct ProcessSummary {
  ProcessReport last;                      // the last status heard
  std::string channel;                     // where it was heard
  std::string state;                       // last.state, "silent", or "stopped" (said "stopping")
  int64_t statuses = 0;                    // [messages] status messages heard
  int64_t first_heard_utime = 0;           // [us] receive time of the first status
  int64_t last_heard_utime = 0;            // [us] receive time of the last status
  double silent_s = 0;                     // [s] since the last status, at summary time
  std::optional<double> max_status_gap_s;  // [s] largest interval between two statuses
  int64_t status_seq_gaps = 0;             // [messages] status messages lost (sequence numbers)
  int64_t restarts = 0;                    // times the pid changed
  int64_t peak_rss_bytes = 0;              // [bytes] largest reported resident memory
};

class ProcessTracker {
 public:
  // A process not heard for longer than `status_timeout_s` [s] is "silent".
  explicit ProcessTracker(double status_timeout_s) : status_timeout_s_(status_timeout_s) {}

  // A status heard on `channel` at `receive_utime` [us] (local clock).
  void add(const std::string& channel, int64_t receive_utime, const ProcessReport& report);

  // Every process heard so far, by name, judged at `now_utime` [us] (local clock).
  std::map<std::string, ProcessSummary> summary(int64_t now_utime) const;

 private:
  double status_timeout_s_;
  std::map<std::string, ProcessSummary> processes_;
};

// True when the process said it was stopping or had stopped, i.e. it ended on purpose.
bool said_stopping(const std::string& state);

}  // namespace traverse::validate
