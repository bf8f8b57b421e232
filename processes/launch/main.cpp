// traverse-launch (called by scripts/run-graph.sh): runs one instance of the process graph on a
// private LCM URL (or the deployment's, for a graph on several machines: each process on its
// host, live_run.cpp). Starts traverse-record (OUTDIR/run.lcmlog), traverse-monitor
// (OUTDIR/monitor.json) and the deployment's processes, waits until each has published its first
// status, replays the input log with lcm-logplayer, and when playback ends (or on SIGINT/SIGTERM)
// stops the processes, then the monitor, then the logger. The summary (also OUTDIR/run-graph.json)
// ends with one JSON line. Exit 0 when every process lasted to the end and stopped cleanly and the
// run's verdict is ok (input log readable and undamaged, the monitor's thresholds kept:
// run_checks.hpp), 1 when a process died or had to be killed, 2 for bad arguments, 3 when the
// verdict fails, 130 when interrupted. Offline, the monitor judges the recorded run afterwards
// (--replay).
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <regex>

#include "config.hpp"
#include "control.hpp"
#include "deployment.hpp"
#include "frontend_control.hpp"
#include "process.hpp"
#include "run_modes.hpp"
#include "session.hpp"
#include "version.hpp"

namespace fs = std::filesystem;
using traverse::launch::Options;
using traverse::launch::Plan;

namespace {

void add_options(CLI::App& app, Options& o) {
  app.add_option("--deploy", o.deploy, "deployment YAML (configs/deploy/); required to run");
  app.add_option("--log", o.log,
                 "input LCM log to replay (the first host only; without one, live until stopped)");
  app.add_option("--host", o.host,
                 "the deployment host this launcher is (default: the first); it starts that "
                 "host's processes and those of hosts with a network namespace");
  app.add_option("--out", o.out, "output directory (run.lcmlog, monitor.json, <name>.log)")
      ->required();
  app.add_option("--speed", o.speed,
                 "playback speed multiplier (0: as fast as possible; expect losses)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--stages", o.stages, "processes to start: names separated by commas, or all")
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL of the run (default: a private udpm port)");
  app.add_option("--root", o.root, "directory relative config paths in the deployment start from")
      ->capture_default_str();
  app.add_option("--bin-dir", o.bin_dir,
                 "where traverse-* programs are (default: beside this one)");
  app.add_option("--grace", o.grace_s, "[s] after playback ends, before stopping processes")
      ->capture_default_str();
  app.add_option("--stop-timeout", o.stop_timeout_s, "[s] from SIGINT to SIGTERM")
      ->capture_default_str();
  app.add_option("--ready-timeout", o.ready_timeout_s,
                 "[s] to wait for every process's first status before replaying")
      ->capture_default_str();
  app.add_option("--control", o.control,
                 "to the launcher running with this --out: start, stop or restart --process NAME, "
                 "status (prints OUTDIR/processes.json), or frontend --kind KIND (swaps the "
                 "frontend of the running graph)");
  app.add_option("--process", o.process, "with --control: the process");
  app.add_option("--kind", o.kind, "with --control frontend: hector or icp");
  app.add_option("--resume", o.resume,
                 "a session's earlier output folder: its state/ (the processes' saved state) is "
                 "copied into --out and the processes go on from it; without it --out's state/ "
                 "is cleared");
  app.add_flag("--offline", o.offline,
               "no bus: run the stages one after another on the log (--replay/--record), as "
               "fast as they compute and without transport loss; --speed is ignored");
  app.add_option("--record-without", o.record_without,
                 "channels left out of run.lcmlog: a regex over the whole channel name, e.g. "
                 "'SCAN_.*|IMU' (the processes and the monitor still hear them)");
  app.add_flag("--raise-rmem-max", o.raise_rmem_max,
               "as root, raise net.core.rmem_max (system-wide) to the URL's recv_buf_size");
}

std::string find_program(const std::string& program, const std::string& bin_dir) {
  if (program.find('/') != std::string::npos) return fs::absolute(program).string();
  const fs::path in_bin = fs::path(bin_dir) / program;
  return fs::exists(in_bin) ? in_bin.string() : "";
}

std::string find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/bin:/bin";
  for (std::size_t at = 0; at <= dirs.size();) {
    const std::size_t end = std::min(dirs.find(':', at), dirs.size());
    const fs::path p = fs::path(dirs.substr(at, end - at)) / program;
    if (access(p.c_str(), X_OK) == 0) return p.string();
    at = end + 1;
  }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app(
      "Runs one instance of the Traverse process graph on a private LCM URL, replaying "
      "an LCM log through it and recording every channel",
      "traverse-launch");
  Options o;
  add_options(app, o);
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  if (o.control == "frontend") {
    return traverse::launch::send_frontend_control(
        o.out, o.process.empty() ? "frontend" : o.process, o.kind, o.stop_timeout_s + 10.0);
  }
  if (!o.control.empty()) {
    return traverse::launch::send_control(o.out, o.control, o.process, o.stop_timeout_s + 30.0);
  }
  if (o.deploy.empty()) {
    std::fprintf(stderr, "run-graph: --deploy is required\n");
    return traverse::kConfigErrorExitCode;
  }
  try {
    std::regex check(o.record_without);
  } catch (const std::regex_error& e) {
    std::fprintf(stderr, "run-graph: --record-without '%s' is not a regular expression: %s\n",
                 o.record_without.c_str(), e.what());
    return traverse::kConfigErrorExitCode;
  }
  traverse::launch::Deployment deployment;
  try {
    deployment = traverse::launch::load_deployment(o.deploy);
  } catch (const traverse::ConfigError& e) {
    std::fprintf(stderr, "run-graph: %s\n", e.what());
    return traverse::kConfigErrorExitCode;
  }
  std::string error;
  const auto stages = traverse::launch::select_stages(deployment, o.stages, error);
  if (!stages) {
    std::fprintf(stderr, "run-graph: %s: %s\n", o.deploy.c_str(), error.c_str());
    return traverse::kConfigErrorExitCode;
  }
  if (o.bin_dir.empty()) o.bin_dir = fs::read_symlink("/proc/self/exe").parent_path().string();
  if (o.host.empty() && !deployment.hosts.empty()) o.host = deployment.hosts.front().name;
  const traverse::launch::HostSpec* self = deployment.find_host(o.host);
  if (!o.host.empty() && !self) {
    std::fprintf(stderr, "run-graph: --host '%s' is not one of the hosts of %s\n", o.host.c_str(),
                 o.deploy.c_str());
    return traverse::kConfigErrorExitCode;
  }
  Plan plan;
  plan.host = o.host;
  plan.records = deployment.hosts.empty() || o.host == deployment.hosts.front().name;
  plan.lcm_url = deployment.lcm_url;
  if (!plan.records && (!o.log.empty() || o.offline)) {
    std::fprintf(stderr, "run-graph: only the first host (%s) replays a log or runs offline\n",
                 deployment.hosts.front().name.c_str());
    return traverse::kConfigErrorExitCode;
  }
  if ((o.offline || !o.log.empty()) && !fs::is_regular_file(o.log)) {
    std::fprintf(stderr, "run-graph: input log not found: %s\n", o.log.c_str());
    return traverse::kConfigErrorExitCode;
  }

  // Resolve every program and config before starting anything.
  plan.logger = find_program("traverse-record", o.bin_dir);
  plan.player = find_on_path("lcm-logplayer");
  const std::string monitor = find_program("traverse-monitor", o.bin_dir);
  const std::vector<std::pair<std::string, std::string>> tools = {
      {"traverse-record (in " + o.bin_dir + ")", plan.logger},
      {"lcm-logplayer", plan.player},
      {"traverse-monitor (in " + o.bin_dir + ")", monitor}};
  for (const auto& [what, path] : tools) {
    if (path.empty()) {
      std::fprintf(stderr, "run-graph: %s not found\n", what.c_str());
      return traverse::kConfigErrorExitCode;
    }
  }
  plan.stop_timeout_s = o.stop_timeout_s;
  for (const auto& s : traverse::launch::started_here(deployment, *stages, o.host)) {
    const traverse::launch::HostSpec* host = deployment.host_of(s);
    traverse::launch::Planned p{s.name,
                                {find_program(s.program, o.bin_dir)},
                                s.host,
                                host && host != self ? host->netns : ""};
    if (p.argv[0].empty()) {
      std::fprintf(stderr, "run-graph: %s: program '%s' of '%s' not found in %s\n",
                   o.deploy.c_str(), s.program.c_str(), s.name.c_str(), o.bin_dir.c_str());
      return traverse::kConfigErrorExitCode;
    }
    if (!s.config.empty()) {
      const fs::path cfg =
          fs::path(s.config).is_absolute() ? fs::path(s.config) : fs::path(o.root) / s.config;
      if (!fs::is_regular_file(cfg)) {
        std::fprintf(stderr, "run-graph: %s: config of '%s' not found: %s\n", o.deploy.c_str(),
                     s.name.c_str(), cfg.c_str());
        return traverse::kConfigErrorExitCode;
      }
      p.argv.insert(p.argv.end(), {"--config", fs::absolute(cfg).string()});
    }
    p.argv.insert(p.argv.end(), {"--name", s.name});
    for (const auto& a : s.args) {
      p.argv.push_back(traverse::launch::expand_out_dir(a, fs::absolute(o.out).string()));
    }
    plan.stop_timeout_s = std::max(plan.stop_timeout_s, s.stop_timeout_s);
    plan.stages.push_back(std::move(p));
    plan.specs.push_back(s);
  }
  for (const auto& s : *stages) {
    bool here = false;
    for (const auto& p : plan.stages) here = here || p.name == s.name;
    if (!here) plan.elsewhere.push_back(s.name + " (" + s.host + ")");
  }
  if (o.offline && !plan.elsewhere.empty()) {
    std::fprintf(stderr, "run-graph: --offline runs every stage here; %s is on another host\n",
                 plan.elsewhere.front().c_str());
    return traverse::kConfigErrorExitCode;
  }

  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (!fs::is_directory(o.out)) {
    std::fprintf(stderr, "run-graph: cannot create %s\n", o.out.c_str());
    return 1;
  }
  if (const auto problem = traverse::launch::prepare_state(o.out, o.resume)) {
    std::fprintf(stderr, "run-graph: %s\n", problem->c_str());
    return traverse::kConfigErrorExitCode;
  }
  traverse::install_stop_signals();  // SIGINT, SIGTERM: stop the graph (stop_requested)
  signal(SIGPIPE, SIG_IGN);
  const fs::path monitor_config = fs::path(o.root) / "configs" / "monitor.yaml";
  plan.monitor_argv = {monitor, "--name", "monitor", "--out",
                       (fs::absolute(o.out) / "monitor.json").string()};
  if (fs::is_regular_file(monitor_config)) {
    plan.monitor_argv.insert(plan.monitor_argv.end(),
                             {"--config", fs::absolute(monitor_config).string()});
  }
  if (o.offline) return traverse::launch::run_offline(o, plan, fs::absolute(o.out));
  // This launcher's own host stands in a network namespace: enter it, so the helpers (logger,
  // monitor, replay) and the port chosen are that host's.
  if (self && !self->netns.empty() && !traverse::launch::enter_netns(self->netns, error)) {
    std::fprintf(stderr, "run-graph: %s\n", error.c_str());
    return 1;
  }
  return traverse::launch::run_live(o, plan, fs::absolute(o.out));
}
