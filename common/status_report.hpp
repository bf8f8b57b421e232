// One process_status_t summed over its channels and read from its counters: what the monitor
// judges and the viewer shows of every process's health. (No LCM include: the cores that use the
// struct stay free of it; report_of's caller has the message type.)
#pragma once

#include <cstdint>
#include <string>

namespace traverse {

class process_status_t;

struct StatusReport {
  std::string process;  // process name
  std::string host;
  int32_t pid = 0;
  int64_t seq = 0;        // +1 per status message
  int64_t utime = 0;      // [us] wall-clock time the status was taken
  std::string state;      // "running", "stopping", free text after a colon
  double uptime_s = 0;    // [s]
  double cpu_s = 0;       // [s] user + system CPU time
  int64_t rss_bytes = 0;  // [bytes]
  // Sums over the process's channels since it started [messages].
  int64_t received = 0, published = 0, decode_failures = 0, out_of_order = 0, missed = 0,
          handler_errors = 0;
  // From its counters: messages rejected (cannot be right, beyond a limit) and stamps dropped as
  // far from their neighbours, summed over channels; what its receive queue dropped; for an
  // offline run, the events it replayed and the damaged records met in its input (-1: live).
  int64_t rejected = 0, stamp_outliers = 0, queue_dropped = 0;
  int64_t replay_events = -1, replay_damaged_records = -1;
};

StatusReport report_of(const process_status_t& status);

}  // namespace traverse
