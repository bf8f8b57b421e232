#include "run_summary.hpp"

#include <cmath>

namespace traverse::validate {

void judge(RunSummary& s, const Thresholds& t) {
  s.notes.clear();
  // Live, a message's event time is when the monitor's socket received it, by the machine's wall
  // clock, and two messages received within a fraction of a millisecond can be stamped the wrong
  // way round; the stream itself went backwards only where the messages' own times did. A step
  // back of the receive time alone is therefore said, not a verdict (a log's event times are
  // judged: they are what a replay delivers by).
  ChannelSummaries judged = s.channels;
  for (auto& [name, c] : judged) {
    const int64_t receive_only = c.backwards - c.utime_backwards;
    if (!t.timing || receive_only <= 0) continue;
    s.notes.push_back(name + ": received " + std::to_string(receive_only) +
                      " messages stamped earlier than the one before (up to " +
                      std::to_string(std::lround(1e6 * c.max_backstep_s.value_or(0.0))) +
                      " us), their own times in order");
    c.backwards = c.utime_backwards;
  }
  s.problems = channel_problems(judged);
  // The monitor listens like any process; on a loaded machine its own socket can overflow while
  // every process of the graph keeps up (each counts what it missed: process_problems below).
  // Its own misses are therefore said, not a verdict on the run.
  for (const auto& [name, c] : s.channels) {
    if (c.seq_gaps > t.max_seq_gaps) {
      s.notes.push_back(name + ": the monitor missed " + std::to_string(c.seq_gaps) +
                        " messages (sequence numbers skipped; no process of the graph reported "
                        "them lost unless a problem says so)");
    }
  }
  for (auto& p : process_problems(s.processes, t)) s.problems.push_back(std::move(p));
  if (s.status_decode_failures > 0) {
    s.problems.push_back(std::to_string(s.status_decode_failures) +
                         " messages on STATUS_ channels are not a process status");
  }
  s.ok = s.problems.empty();
}

std::string to_json(const RunSummary& s) {
  Json j;
  j["lcm_url"] = s.lcm_url;
  j["start_utime"] = s.start_utime;
  j["end_utime"] = s.end_utime;
  j["duration_s"] = json_significant(1e-6 * static_cast<double>(s.end_utime - s.start_utime), 9);
  j["events"] = s.events;
  j["status_decode_failures"] = s.status_decode_failures;
  j["channels"] = channels_json(s.channels);
  j["processes"] = processes_json(s.processes);
  j["problems"] = s.problems;
  j["notes"] = s.notes;
  j["ok"] = s.ok;
  return json_line(j);
}

std::string to_text(const RunSummary& s) {
  std::string out = "heard " + std::to_string(s.events) + " messages on " +
                    std::to_string(s.channels.size()) + " channels from " +
                    std::to_string(s.processes.size()) + " processes\n\n";
  out += channel_table(s.channels) + "\n" + process_table(s.processes) + "\n";
  for (const auto& p : s.problems) out += "problem: " + p + "\n";
  for (const auto& n : s.notes) out += "note: " + n + "\n";
  out += s.ok ? "run is clean\n" : "run has problems\n";
  return out;
}

}  // namespace traverse::validate
