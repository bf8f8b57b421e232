// The launcher's two ways of running a planned graph (main.cpp plans it from the deployment):
// live on an LCM bus, with the processes started where the deployment puts them, or offline,
// stage after stage on the log.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "deployment.hpp"
#include "supervisor.hpp"

namespace traverse::launch {

struct Options {
  std::string deploy, log, out, stages = "all", lcm_url, root = ".", bin_dir, host;
  std::string control, process;  // --control COMMAND [--process NAME]: a running launcher
  std::string record_without;    // channels (a regex over the whole name) run.lcmlog leaves out
  std::string kind;              // --control frontend --kind KIND
  std::string resume;            // --resume EARLIER_OUT: the session's saved state
  double speed = 1.0, grace_s = 2.0, stop_timeout_s = 5.0, ready_timeout_s = 10.0;
  bool offline = false, raise_rmem_max = false;
};

// A stage of the graph, resolved: instance name, the command line that starts it (without the
// LCM URL), and where it runs.
struct Planned {
  std::string name;
  std::vector<std::string> argv;
  std::string host;   // deployment host, "" when it names none
  std::string netns;  // network namespace to start it in, "" for the launcher's own
};

struct Plan {
  std::vector<Planned> stages;         // what this launcher starts, in graph order
  std::vector<StageSpec> specs;        // the same stages as the deployment gives them
  std::vector<std::string> elsewhere;  // "name (host)" of stages other launchers start
  std::vector<std::string> monitor_argv;
  std::string logger, player;   // traverse-record, lcm-logplayer
  std::string host;             // the host this launcher is ("" when the deployment has none)
  bool records = true;          // the first host: logger, monitor and the log's replay
  std::string lcm_url;          // from the deployment, "" for a private one
  double stop_timeout_s = 5.0;  // [s] the longest any stage may need to stop
};

// Says at once when a child ends on its own with a failure.
void announce(const std::vector<const Child*>& ended);

int run_offline(const Options& o, const Plan& plan, const std::filesystem::path& out_dir);
int run_live(Options& o, const Plan& plan, const std::filesystem::path& out_dir);

}  // namespace traverse::launch
