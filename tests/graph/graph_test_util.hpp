// Helpers of the program-wide tests: run a shell command with a time limit, read LCM logs back.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "traverse/pose2d_t.hpp"

namespace traverse::graph_test {

struct CommandResult {
  int exit_code = -1;  // 124 when the time limit killed it
  std::string output;  // stdout and stderr
};

// Runs `command` through /bin/sh with `timeout_s`, capturing output.
CommandResult run(const std::string& command, int timeout_s);

std::string bin_dir();                                    // TRAVERSE_BIN_DIR
std::vector<std::string> traverse_programs();             // names of bin/traverse-*, e.g. "carmen"
std::filesystem::path temp_dir(const std::string& name);  // fresh, under the system temp dir

// The whole text of a file ("" when it cannot be read).
std::string read_text(const std::filesystem::path& path);
// The number after "KEY": in a script's JSON line (Python's spacing); fails the test and returns
// -1 when the key is missing.
double json_number(const std::string& json, const std::string& key);
// The JSON object an evaluation script prints last (its output from the last "{\"route\""); empty,
// failing the test, when there is none.
std::string route_json(const std::string& output);
// scripts/eval-route.sh ARGS with this build's programs (10 min at most): its JSON line, failing
// the test when the script fails.
std::string eval_route(const std::string& args);
// The pid a launcher's processes.json gives `name`, 0 when it is not there (yet) or not running.
int running_pid(const std::filesystem::path& processes_json, const std::string& name);

// Messages per channel in an LCM log; fails the test if the log is damaged.
std::map<std::string, int64_t> count_channels(const std::string& lcm_log);

struct StatusMessage {
  std::string channel;
  int64_t utime = 0;  // [us]
  int32_t pid = 0;
  std::string host;
  std::map<std::string, int64_t> missed;  // [messages] per channel, sequence numbers skipped
};
std::vector<StatusMessage> statuses(const std::string& lcm_log);

// Position RMSE [m] of a run's final trajectory on `channel` (run_dir/run.lcmlog) against the
// ground truth, by traverse-evaluator; -1 (and a test failure) when it fails.
double position_rmse(const std::filesystem::path& run_dir, const std::string& channel);
// Waits until a launcher's processes.json shows its log player running (at most 60 s), then
// `delay_s` more, and SIGKILLs process `victim`; its pid, 0 when it was not running.
int kill_into_replay(const std::filesystem::path& processes_json, const std::string& victim,
                     double delay_s);

// The number of points of a PLY cloud (its header), -1 when it cannot be read.
int64_t cloud_points(const std::filesystem::path& ply);
// The occupied voxels of an OctoMap file (.bt), as keys; none when it cannot be read.
std::set<std::tuple<int, int, int>> occupied_voxels(const std::filesystem::path& bt);
// The pose2d_t messages of `channel` in an LCM log.
std::vector<pose2d_t> poses_on(const std::string& lcm_log, const std::string& channel);

// A short LCM log made by traverse-carmen from the first `lines` lines of the Intel CARMEN log.
std::string short_intel_log(const std::filesystem::path& dir, int lines);

}  // namespace traverse::graph_test
