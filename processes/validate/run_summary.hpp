// The summary of a live run as the monitor saw it: every channel (same checks as for a log) and
// every process that published status, with the problems that make the run not ok.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "report.hpp"

namespace traverse::validate {

struct RunSummary {
  std::string lcm_url;
  int64_t start_utime = 0;             // [us] when listening started (local clock)
  int64_t end_utime = 0;               // [us] when the summary was taken
  int64_t events = 0;                  // [messages] heard on all channels
  int64_t status_decode_failures = 0;  // [messages] on STATUS_* that were not a process status
  ChannelSummaries channels;
  ProcessSummaries processes;
  std::vector<std::string> problems;  // empty when ok
  // Said, not failed: messages the monitor itself missed (its own reception; the graph's
  // processes count and report their own losses, which are problems).
  std::vector<std::string> notes;
  bool ok = false;
};

// Fills problems and ok from the channels and processes.
void judge(RunSummary& s, const Thresholds& t = {});

// One line of JSON: lcm_url, duration_s, events, channels, processes, problems, notes, ok.
std::string to_json(const RunSummary& s);

// The human-readable report: channel table, process table, verdict.
std::string to_text(const RunSummary& s);

}  // namespace traverse::validate
