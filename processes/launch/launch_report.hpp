// The launcher's account of a run: how each child ended, which failed, as text and one JSON line.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "supervisor.hpp"

namespace traverse::launch {

struct ChildReport {
  std::string name;
  std::string program;
  std::string outcome;  // e.g. "exit 0 after SIGINT"
  int exit_code = -1;
  int signal = 0;
  bool failed = false;
  std::string why;  // for a failure: "died", "had to be killed", "ended early"
};

struct RunReport {
  std::string url;
  std::string out_dir;
  double replay_s = 0.0;    // [s] wall time of the playback
  double duration_s = 0.0;  // [s] wall time of the whole run
  bool interrupted = false;
  std::set<std::string> not_ready;  // processes with no status before playback
  std::vector<ChildReport> children;
  std::vector<std::string> failed;
  std::vector<std::string> verdict_problems;  // input log, monitor's verdict (run_checks.hpp)
  bool ok = false;
};

// Exit code when every process ran to the end but the run's verdict fails.
inline constexpr int kVerdictFailedExitCode = 3;

// Fills `report` from the ended children; returns the launcher's exit code (0 ok, 1 a failure,
// 3 the verdict failed, 130 interrupted without failure).
int finish_report(RunReport& report, const Supervisor& sup, bool all_started);

std::string to_text(const RunReport& report);
std::string to_json(const RunReport& report);

}  // namespace traverse::launch
