// traverse-launch (called by scripts/run-graph.sh): runs one instance of the process graph on a
// private LCM URL. Starts lcm-logger (OUTDIR/run.lcmlog), traverse-monitor (OUTDIR/monitor.json)
// and the deployment's processes, waits until each has published its first status, replays the
// input log with lcm-logplayer, and when playback ends (or on SIGINT/SIGTERM) stops the processes,
// then the monitor, then the logger. The summary (also OUTDIR/run-graph.json) ends with one JSON
// line. Exit 0 when every process lasted to the end and stopped cleanly and the run's verdict is
// ok (input log readable and undamaged, the monitor's thresholds kept: run_checks.hpp), 1 when a
// process died or had to be killed, 2 for bad arguments, 3 when the verdict fails, 130 when
// interrupted. Offline, the monitor judges the recorded run afterwards (--replay).
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <set>
#include <thread>

#include "channels.hpp"
#include "config.hpp"
#include "deployment.hpp"
#include "launch_report.hpp"
#include "run_checks.hpp"
#include "supervisor.hpp"
#include "version.hpp"

namespace fs = std::filesystem;
using traverse::launch::Supervisor;

namespace {

std::atomic<bool> g_interrupted{false};
void on_signal(int) { g_interrupted = true; }

struct Options {
  std::string deploy, log, out, stages = "all", lcm_url, root = ".", bin_dir;
  double speed = 1.0, grace_s = 2.0, stop_timeout_s = 5.0, ready_timeout_s = 10.0;
  bool offline = false, raise_rmem_max = false;
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--deploy", o.deploy, "deployment YAML (configs/deploy/)")->required();
  app.add_option("--log", o.log, "input LCM log to replay")->required();
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
  app.add_flag("--offline", o.offline,
               "no bus: run the stages one after another on the log (--replay/--record), as "
               "fast as they compute and without transport loss; --speed is ignored");
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

// Says at once when a child ends on its own with a failure.
void announce(const std::vector<const traverse::launch::Child*>& ended) {
  for (const auto* c : ended) {
    if (c->name != "logplayer" && c->died()) {
      std::fprintf(stderr, "run-graph: '%s' died during the run: %s (see %s)\n", c->name.c_str(),
                   c->outcome().c_str(), c->log_path.c_str());
    }
  }
}

// Waits until every named process has published on its status channel, a child ended, or the
// timeout; returns the names that never reported.
std::set<std::string> wait_until_ready(const std::string& url, std::set<std::string> waiting,
                                       Supervisor& sup, double timeout_s) {
  lcm::LCM lcm(url);
  if (!lcm.good()) return waiting;
  struct Handler {
    std::set<std::string>* waiting;
    void on(const lcm::ReceiveBuffer*, const std::string& channel) {
      for (auto it = waiting->begin(); it != waiting->end(); ++it) {
        if (traverse::channels::status_channel(*it) == channel) {
          waiting->erase(it);
          return;
        }
      }
    }
  } handler{&waiting};
  lcm.subscribe("STATUS_.*", &Handler::on, &handler);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!waiting.empty() && !g_interrupted && std::chrono::steady_clock::now() < deadline) {
    lcm.handleTimeout(50);
    const auto ended = sup.reap();
    announce(ended);
    for (const auto* c : ended) waiting.erase(c->name);
  }
  return waiting;
}

}  // namespace

// A stage of the graph, resolved: instance name and the command line that starts it.
struct Planned {
  std::string name;
  std::vector<std::string> argv;
};

// --offline: each stage reads the previous stage's record (the first reads the input log) with
// --replay and writes its own with --record: everything the input had plus what the stage
// published. The last record becomes run.lcmlog; the ones in between are deleted as soon as the
// next stage has read them. Deterministic: the same input gives the same messages.
int run_offline(const Options& o, const std::vector<Planned>& planned, const fs::path& out_dir,
                std::vector<std::string> monitor_argv) {
  const auto t0 = std::chrono::steady_clock::now();
  Supervisor sup;
  std::string error;
  bool ok = true;
  fs::path input = fs::absolute(o.log);
  std::vector<std::string> names;
  for (const auto& [name, planned_argv] : planned) {
    std::vector<std::string> argv = planned_argv;
    const fs::path record = out_dir / (name + ".lcmlog");
    argv.insert(argv.end(), {"--replay", input.string(), "--record", record.string()});
    std::fprintf(stderr, "run-graph: offline stage '%s' on %s\n", name.c_str(), input.c_str());
    if (!sup.spawn(name, argv, (out_dir / (name + ".log")).string(), error)) {
      std::fprintf(stderr, "run-graph: %s\n", error.c_str());
      ok = false;
      break;
    }
    names.push_back(name);
    while (sup.find(name)->running && !g_interrupted) {
      announce(sup.reap());
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (g_interrupted) break;
    if (sup.find(name)->died()) {
      ok = false;
      break;
    }
    if (input != fs::absolute(o.log)) fs::remove(input);
    input = record;
  }
  sup.stop(names, o.stop_timeout_s);
  std::error_code ec;
  if (ok && !g_interrupted && input != fs::absolute(o.log)) {
    fs::rename(input, out_dir / "run.lcmlog", ec);
  } else if (ok && !g_interrupted) {
    fs::copy_file(input, out_dir / "run.lcmlog", fs::copy_options::overwrite_existing, ec);
  }
  traverse::launch::RunReport report;
  report.url = "offline";
  report.out_dir = out_dir.string();
  report.verdict_problems = traverse::launch::input_log_problems(o.log);
  if (ok && !g_interrupted && !ec) {
    // The monitor judges the recorded run: what each stage reported in its statuses.
    std::vector<std::string> argv = monitor_argv;
    argv.insert(argv.end(), {"--replay", (out_dir / "run.lcmlog").string()});
    std::fprintf(stderr, "run-graph: the monitor judges %s\n", (out_dir / "run.lcmlog").c_str());
    if (sup.spawn("monitor", argv, (out_dir / "monitor.log").string(), error)) {
      while (sup.find("monitor")->running && !g_interrupted) {
        sup.reap();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      sup.stop({"monitor"}, o.stop_timeout_s);
    }
    for (auto& p : traverse::launch::monitor_problems((out_dir / "monitor.json").string())) {
      report.verdict_problems.push_back(std::move(p));
    }
  }
  report.interrupted = g_interrupted;
  report.duration_s = report.replay_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int rc = traverse::launch::finish_report(report, sup, ok);
  if (ec) {
    std::fprintf(stderr, "run-graph: cannot write %s: %s\n", (out_dir / "run.lcmlog").c_str(),
                 ec.message().c_str());
    rc = 1;
  }
  const std::string json = traverse::launch::to_json(report);
  std::ofstream(out_dir / "run-graph.json") << json << '\n';
  std::fputs(traverse::launch::to_text(report).c_str(), stdout);
  std::puts(json.c_str());
  std::fflush(stdout);
  return rc;
}

int main(int argc, char** argv) {
  CLI::App app(
      "Runs one instance of the Traverse process graph on a private LCM URL, replaying "
      "an LCM log through it and recording every channel",
      "traverse-launch");
  Options o;
  add_options(app, o);
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

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
  if (!fs::is_regular_file(o.log)) {
    std::fprintf(stderr, "run-graph: input log not found: %s\n", o.log.c_str());
    return traverse::kConfigErrorExitCode;
  }

  // Resolve every program and config before starting anything.
  std::vector<Planned> planned;
  const std::string logger = find_on_path("lcm-logger"), player = find_on_path("lcm-logplayer");
  const std::string monitor = find_program("traverse-monitor", o.bin_dir);
  const std::vector<std::pair<std::string, std::string>> tools = {
      {"lcm-logger", logger},
      {"lcm-logplayer", player},
      {"traverse-monitor (in " + o.bin_dir + ")", monitor}};
  for (const auto& [what, path] : tools) {
    if (path.empty()) {
      std::fprintf(stderr, "run-graph: %s not found\n", what.c_str());
      return traverse::kConfigErrorExitCode;
    }
  }
  double stop_timeout_s = o.stop_timeout_s;  // the longest any stage may need
  for (const auto& s : *stages) {
    Planned p{s.name, {find_program(s.program, o.bin_dir)}};
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
    stop_timeout_s = std::max(stop_timeout_s, s.stop_timeout_s);
    planned.push_back(std::move(p));
  }

  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (!fs::is_directory(o.out)) {
    std::fprintf(stderr, "run-graph: cannot create %s\n", o.out.c_str());
    return 1;
  }
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
  const fs::path monitor_config = fs::path(o.root) / "configs" / "monitor.yaml";
  std::vector<std::string> monitor_argv = {monitor, "--name", "monitor", "--out",
                                           (fs::absolute(o.out) / "monitor.json").string()};
  if (fs::is_regular_file(monitor_config)) {
    monitor_argv.insert(monitor_argv.end(), {"--config", fs::absolute(monitor_config).string()});
  }
  if (o.offline) return run_offline(o, planned, fs::absolute(o.out), monitor_argv);
  std::optional<traverse::launch::PortLease> lease;
  if (o.lcm_url.empty()) {
    lease = traverse::launch::reserve_port(fs::temp_directory_path() / "traverse-lcm-ports", 20000,
                                           29999);
    if (!lease) {
      std::fprintf(stderr, "run-graph: no free LCM port in 20000..29999\n");
      return 1;
    }
    o.lcm_url = traverse::launch::private_url(lease->port(), 8 << 20);
  }
  const std::string rmem = traverse::launch::check_rmem_max(
      traverse::launch::recv_buf_size_of(o.lcm_url), o.raise_rmem_max);
  if (!rmem.empty()) std::fprintf(stderr, "run-graph: %s\n", rmem.c_str());

  const auto t0 = std::chrono::steady_clock::now();
  const fs::path out_dir = fs::absolute(o.out);
  const std::string url_arg = "--lcm-url=" + o.lcm_url;
  Supervisor sup;
  monitor_argv.insert(monitor_argv.begin() + 1, {"--lcm-url", o.lcm_url});
  // LCM_SELF_TEST is udpm's own start-up probe, not part of the run: not recorded.
  bool spawned = sup.spawn("logger",
                           {logger, "-f", "-q", "-v", "--channel=LCM_SELF_TEST", url_arg,
                            (out_dir / "run.lcmlog").string()},
                           (out_dir / "logger.log").string(), error) &&
                 sup.spawn("monitor", monitor_argv, (out_dir / "monitor.log").string(), error);
  std::set<std::string> waiting = {"monitor"};
  std::vector<std::string> stage_names;
  for (const auto& p : planned) {
    std::vector<std::string> argv = p.argv;
    argv.insert(argv.begin() + 1, {"--lcm-url", o.lcm_url});
    spawned = spawned && sup.spawn(p.name, argv, (out_dir / (p.name + ".log")).string(), error);
    waiting.insert(p.name);
    stage_names.push_back(p.name);
  }
  if (!spawned) std::fprintf(stderr, "run-graph: %s\n", error.c_str());
  std::fprintf(stderr, "run-graph: LCM URL %s, %zu processes, output in %s\n", o.lcm_url.c_str(),
               planned.size(), out_dir.c_str());

  traverse::launch::RunReport report;
  report.url = o.lcm_url;
  report.out_dir = out_dir.string();
  report.verdict_problems = traverse::launch::input_log_problems(o.log);
  report.not_ready = wait_until_ready(o.lcm_url, waiting, sup, o.ready_timeout_s);
  // The logger is listening once it has written something (the statuses just heard).
  const auto logger_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  const auto logged_something = [&] {
    std::error_code size_ec;
    const auto size = fs::file_size(out_dir / "run.lcmlog", size_ec);
    return !size_ec && size > 0;
  };
  while (!g_interrupted && std::chrono::steady_clock::now() < logger_deadline &&
         !logged_something()) {
    announce(sup.reap());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (const auto& n : report.not_ready) {
    std::fprintf(stderr, "run-graph: no status from '%s' within %.1f s; replaying anyway\n",
                 n.c_str(), o.ready_timeout_s);
  }

  // Replay, watching for processes that die meanwhile.
  char speed[32];
  std::snprintf(speed, sizeof(speed), "--speed=%g", o.speed);
  if (spawned && !g_interrupted) {
    spawned = sup.spawn("logplayer", {player, speed, url_arg, fs::absolute(o.log).string()},
                        (out_dir / "logplayer.log").string(), error);
  }
  const auto replay_start = std::chrono::steady_clock::now();
  while (spawned && !g_interrupted) {
    announce(sup.reap());
    const auto* player_child = sup.find("logplayer");
    if (!player_child->running) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  report.replay_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - replay_start).count();
  report.interrupted = g_interrupted;

  // Shut down: playback, then (after a grace period) the graph, the monitor, the logger last so
  // that it records everyone's final status.
  sup.stop({"logplayer"}, 1.0);
  if (!g_interrupted) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.grace_s);
    while (!g_interrupted && std::chrono::steady_clock::now() < until) {
      announce(sup.reap());
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  // The stages stop one at a time in graph order, each given a moment to hand its final messages
  // to the next before that one stops: the backend's last optimisation, then the densifier's
  // settled segments (stopped all at once, the mapper missed the densifier's last 41 messages on
  // office-x2).
  for (const std::string& name : stage_names) {
    sup.stop({name}, stop_timeout_s);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  sup.stop({"monitor"}, o.stop_timeout_s);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // last messages reach the logger
  sup.stop({"logger"}, o.stop_timeout_s);
  report.duration_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!g_interrupted) {
    for (auto& p : traverse::launch::monitor_problems((out_dir / "monitor.json").string())) {
      report.verdict_problems.push_back(std::move(p));
    }
  }

  const int rc = traverse::launch::finish_report(report, sup, spawned);
  const std::string json = traverse::launch::to_json(report);
  std::ofstream(out_dir / "run-graph.json") << json << '\n';
  std::fputs(traverse::launch::to_text(report).c_str(), stdout);
  std::puts(json.c_str());  // the JSON line last
  std::fflush(stdout);
  return rc;
}
