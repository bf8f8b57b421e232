// Commands to a running launcher, per process: start, stop, restart (and status, which only reads
// OUTDIR/processes.json). The client (run-graph.sh --control) writes the request into the run's
// output folder (OUTDIR/control, replaced atomically); the launcher takes it within 50 ms, acts,
// removes it and rewrites processes.json. Local to one machine, like each host's launcher.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "restart_policy.hpp"
#include "supervisor.hpp"

namespace traverse::launch {

struct ControlRequest {
  std::string command;  // "start", "stop" or "restart"
  std::string name;     // process instance name
};

// The pending request of the launcher writing into `out_dir`; nullopt if none.
std::optional<ControlRequest> take_control_request(const std::filesystem::path& out_dir);
// Removes the request once carried out (and processes.json rewritten).
void done_control_request(const std::filesystem::path& out_dir);

// Carries out a request on the launcher's children; returns what was done, one sentence (also
// when it could not be done, e.g. an unknown name). Stopped processes are never restarted by the
// policy; `stop_timeout_s` [s] from SIGINT to SIGTERM.
std::string apply_control(const ControlRequest& r, Supervisor& sup, double stop_timeout_s);

// The client: sends `command` for `name` and waits (up to `timeout_s`) until the launcher took
// it, then prints processes.json; "status" only prints it. Exit code: 0 done, 1 no launcher took
// it (nothing runs there, or no processes.json), 2 a bad command.
int send_control(const std::filesystem::path& out_dir, const std::string& command,
                 const std::string& name, double timeout_s);

}  // namespace traverse::launch
