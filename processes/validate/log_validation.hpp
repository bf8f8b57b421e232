// Validates an LCM log file: streams every event through the StreamAnalyzer, collects the damage
// the LogReader met (with byte offsets; everything readable around it is still read), and judges
// the log: ok when nothing is damaged, every message decodes as its channel's type, and no
// timestamp goes backwards.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lcm_log.hpp"
#include "report.hpp"

namespace traverse::validate {

struct LogValidation {
  std::string log;     // path as given
  uint64_t bytes = 0;  // [bytes] file size
  int64_t events = 0;  // [events] intact events read
  ChannelSummaries channels;
  std::vector<LogDamage> damage;
  std::vector<std::string> problems;  // empty when ok
  bool ok = false;
};

// Throws std::runtime_error if the file cannot be opened.
LogValidation validate_log(const std::string& path);

// One line of JSON: log, bytes, events, channels, damage, problems, ok.
std::string to_json(const LogValidation& v);

// The human-readable report: channel table, damage lines, verdict.
std::string to_text(const LogValidation& v);

}  // namespace traverse::validate
