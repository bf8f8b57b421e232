#include "process_tracker.hpp"

#include <algorithm>

namespace traverse::validate {

bool said_stopping(const std::string& state) {
  // "stopped" is the last status a process sends after its shutdown work (an export): a
  // process heard saying it was not silent afterwards, whatever the time since.
  return state.rfind("stopping", 0) == 0 || state.rfind("stopped", 0) == 0;
}

void ProcessTracker::add(const std::string& channel, int64_t receive_utime,
                         const ProcessReport& report) {
  const std::string name = report.process.empty() ? channel : report.process;
  ProcessSummary& p = processes_[name];
  if (p.statuses == 0) {
    p.first_heard_utime = receive_utime;
  } else {
    // After "stopping" a process does its shutdown work (an export) without statuses.
    const double gap_s = 1e-6 * (receive_utime - p.last_heard_utime);
    if (!said_stopping(p.last.state)) {
      p.max_status_gap_s = std::max(p.max_status_gap_s.value_or(gap_s), gap_s);
    }
    if (report.pid != p.last.pid) {
      ++p.restarts;
    } else if (report.seq > p.last.seq + 1) {
      p.status_seq_gaps += report.seq - p.last.seq - 1;
    }
  }
  ++p.statuses;
  p.last_heard_utime = receive_utime;
  p.channel = channel;
  p.peak_rss_bytes = std::max(p.peak_rss_bytes, report.rss_bytes);
  p.last = report;
}

std::map<std::string, ProcessSummary> ProcessTracker::summary(int64_t now_utime) const {
  std::map<std::string, ProcessSummary> out = processes_;
  for (auto& [name, p] : out) {
    p.silent_s = 1e-6 * (now_utime - p.last_heard_utime);
    if (said_stopping(p.last.state)) {
      p.state = "stopped";
    } else if (p.silent_s > status_timeout_s_) {
      p.state = "silent";
    } else {
      p.state = p.last.state;
    }
  }
  return out;
}

}  // namespace traverse::validate
