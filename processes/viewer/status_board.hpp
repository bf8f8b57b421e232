// The processes' health as the page shows it, from the process_status_t every process publishes
// once a second: message rates in and out [1/s] and CPU [%] from the difference between two
// statuses, and the counts of what went wrong (missed, dropped, rejected, errors). A process whose
// status stopped for longer than stale_after_s is marked stale.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "status_report.hpp"

namespace traverse::viewer {

struct ProcessRow {
  StatusReport last;
  double in_hz = 0, out_hz = 0;  // [1/s] messages received and published
  double cpu_percent = 0;        // [%] of one core
  bool stale = false;
};

class StatusBoard {
 public:
  explicit StatusBoard(double stale_after_s = 3.0) : stale_after_s_(stale_after_s) {}
  // Returns false (and keeps nothing) for a status older than the one held for that process.
  bool update(const StatusReport& report);
  // Marks processes stale whose newest status is older than stale_after_s at `now_utime`.
  void age(int64_t now_utime);
  const std::map<std::string, ProcessRow>& rows() const { return rows_; }

 private:
  double stale_after_s_;
  std::map<std::string, ProcessRow> rows_;
};

}  // namespace traverse::viewer
