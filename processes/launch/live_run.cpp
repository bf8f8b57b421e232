// The live run: the graph's processes on one LCM bus, each started on its deployment host. The
// first host's launcher also records every channel (traverse-record), judges the run
// (traverse-monitor) and replays the input log standing in for the drivers; another host's launcher
// only runs its own processes until it is stopped. Deaths are handled by the deployment's policy.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <set>
#include <thread>

#include "bus.hpp"
#include "channels.hpp"
#include "control.hpp"
#include "launch_report.hpp"
#include "process.hpp"
#include "restart_policy.hpp"
#include "run_checks.hpp"
#include "run_modes.hpp"

namespace fs = std::filesystem;

namespace traverse::launch {
namespace {

fs::path g_out_dir;      // OUTDIR: control requests arrive there
fs::path g_status_path;  // OUTDIR/processes.json
double g_stop_timeout_s = 5.0;

// Every child's state now, replaced atomically (a reader never sees half a file).
void write_status(const Supervisor& sup) {
  if (g_status_path.empty()) return;
  const fs::path tmp = g_status_path.string() + ".tmp";
  std::ofstream(tmp) << processes_json(sup) << '\n';
  std::error_code ec;
  fs::rename(tmp, g_status_path, ec);
}

// Reaps ended children, says which died, applies the restart policy, updates processes.json.
void tick(Supervisor& sup, RestartPolicy& policy) {
  const auto now = RestartPolicy::Clock::now();
  const auto ended = sup.reap();
  announce(ended);
  policy.ended(ended, now);
  const std::size_t events = policy.events().size();
  policy.restart_due(sup, now);
  if (!ended.empty() || policy.events().size() != events) write_status(sup);
  if (const auto request = take_control_request(g_out_dir)) {
    const std::string done = apply_control(*request, sup, g_stop_timeout_s);
    std::fprintf(stderr, "run-graph: %s\n", done.c_str());
    policy.note(done);
    write_status(sup);
    done_control_request(g_out_dir);
  }
}

bool stopping(const RestartPolicy& policy) { return stop_requested() || policy.stop_graph(); }

// Waits while `more()` and the graph is not stopping, ticking every 50 ms, at most `timeout_s`.
template <class F>
void wait_while(Supervisor& sup, RestartPolicy& policy, double timeout_s, F more) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (more() && !stopping(policy) && std::chrono::steady_clock::now() < deadline) {
    tick(sup, policy);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// Waits until every named process has published on its status channel, a child ended, or the
// timeout; returns the names that never reported.
std::set<std::string> wait_until_ready(const std::string& url, std::set<std::string> waiting,
                                       Supervisor& sup, RestartPolicy& policy, double timeout_s) {
  lcm::LCM lcm(url);
  if (!lcm.good()) return waiting;
  struct Handler {
    std::set<std::string>* waiting;
    void on(const lcm::ReceiveBuffer*, const std::string& channel) {
      for (auto it = waiting->begin(); it != waiting->end(); ++it) {
        if (channels::status_channel(*it) == channel) {
          waiting->erase(it);
          return;
        }
      }
    }
  } handler{&waiting};
  lcm.subscribe("STATUS_.*", &Handler::on, &handler)->setQueueCapacity(Bus::kLcmQueueMessages);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!waiting.empty() && !stopping(policy) && std::chrono::steady_clock::now() < deadline) {
    lcm.handleTimeout(50);
    const auto ended = sup.reap();
    announce(ended);
    policy.ended(ended, RestartPolicy::Clock::now());
    for (const auto* c : ended) waiting.erase(c->name);
  }
  return waiting;
}

}  // namespace

void announce(const std::vector<const Child*>& ended) {
  for (const auto* c : ended) {
    if (c->name != "logplayer" && c->died()) {
      std::fprintf(stderr, "run-graph: '%s' died during the run: %s (see %s)\n", c->name.c_str(),
                   c->outcome().c_str(), c->log_path.c_str());
    }
  }
}

int run_live(Options& o, const Plan& plan, const fs::path& out_dir) {
  std::optional<PortLease> lease;
  if (o.lcm_url.empty()) o.lcm_url = plan.lcm_url;
  if (o.lcm_url.empty()) {
    lease = reserve_port(fs::temp_directory_path() / "traverse-lcm-ports", 20000, 29999);
    if (!lease) {
      std::fprintf(stderr, "run-graph: no free LCM port in 20000..29999\n");
      return 1;
    }
    o.lcm_url = private_url(lease->port(), 8 << 20);
  }
  const std::string rmem = check_rmem_max(recv_buf_size_of(o.lcm_url), o.raise_rmem_max);
  if (!rmem.empty()) std::fprintf(stderr, "run-graph: %s\n", rmem.c_str());

  const auto t0 = std::chrono::steady_clock::now();
  const std::string url_arg = "--lcm-url=" + o.lcm_url;
  Supervisor sup;
  RestartPolicy policy(plan.specs);
  std::string error;
  bool spawned = true;
  std::set<std::string> waiting;
  if (plan.records) {
    std::vector<std::string> monitor_argv = plan.monitor_argv;
    monitor_argv.insert(monitor_argv.begin() + 1, {"--lcm-url", o.lcm_url});
    // The channels of --record-without are not recorded (the recorder matches the whole name;
    // it leaves out LCM's start-up probe, LCM_SELF_TEST, itself).
    std::vector<std::string> logger_argv = {
        plan.logger, "--name", "logger", "--force", url_arg, (out_dir / "run.lcmlog").string()};
    if (!o.record_without.empty()) {
      logger_argv.insert(logger_argv.end(), {"--without", o.record_without});
    }
    spawned =
        sup.spawn("logger", logger_argv, (out_dir / "logger.log").string(), error, plan.host) &&
        sup.spawn("monitor", monitor_argv, (out_dir / "monitor.log").string(), error, plan.host);
    waiting.insert("monitor");
  }
  std::vector<std::string> stage_names;
  for (const auto& p : plan.stages) {
    std::vector<std::string> argv = p.argv;
    argv.insert(argv.begin() + 1, {"--lcm-url", o.lcm_url});
    spawned = spawned && sup.spawn(p.name, argv, (out_dir / (p.name + ".log")).string(), error,
                                   p.host, p.netns);
    waiting.insert(p.name);
    stage_names.push_back(p.name);
  }
  if (!spawned) std::fprintf(stderr, "run-graph: %s\n", error.c_str());
  g_out_dir = out_dir;
  g_stop_timeout_s = plan.stop_timeout_s;
  done_control_request(out_dir);  // a request left from an earlier run is not for this one
  g_status_path = out_dir / "processes.json";
  write_status(sup);
  std::ofstream(out_dir / "lcm_url") << o.lcm_url << '\n';  // for --control frontend
  std::error_code ec_ignored;
  std::fprintf(stderr, "run-graph: LCM URL %s, %zu processes, output in %s\n", o.lcm_url.c_str(),
               plan.stages.size(), out_dir.c_str());
  for (const auto& e : plan.elsewhere) {
    std::fprintf(stderr, "run-graph: not started here: %s (its host's launcher starts it)\n",
                 e.c_str());
  }

  RunReport report;
  report.url = o.lcm_url;
  report.out_dir = out_dir.string();
  if (!o.log.empty()) report.verdict_problems = input_log_problems(o.log);
  report.not_ready = wait_until_ready(o.lcm_url, waiting, sup, policy, o.ready_timeout_s);
  if (plan.records) {
    // The logger is listening once it has written something (the statuses just heard).
    wait_while(sup, policy, 2.0, [&] {
      std::error_code size_ec;
      const auto size = fs::file_size(out_dir / "run.lcmlog", size_ec);
      return size_ec || size == 0;
    });
  }
  for (const auto& n : report.not_ready) {
    std::fprintf(stderr, "run-graph: no status from '%s' within %.1f s; going on anyway\n",
                 n.c_str(), o.ready_timeout_s);
  }

  // Replay (or, with no log, run until stopped), watching for processes that die meanwhile.
  const auto replay_start = std::chrono::steady_clock::now();
  if (spawned && !stopping(policy) && !o.log.empty()) {
    char speed[32];
    std::snprintf(speed, sizeof(speed), "--speed=%g", o.speed);
    spawned = sup.spawn("logplayer", {plan.player, speed, url_arg, fs::absolute(o.log).string()},
                        (out_dir / "logplayer.log").string(), error, plan.host);
    write_status(sup);
    if (spawned) wait_while(sup, policy, 1e9, [&] { return sup.find("logplayer")->running; });
  } else if (spawned) {
    wait_while(sup, policy, 1e9, [] { return true; });
  }
  report.replay_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - replay_start).count();
  report.interrupted = stop_requested();

  // Shut down: playback, then (after a grace period) the graph, the monitor, the logger last so
  // that it records everyone's final status.
  if (sup.find("logplayer")) sup.stop({"logplayer"}, 1.0);
  wait_while(sup, policy, o.grace_s, [] { return true; });
  policy.cancel();
  // The stages stop one at a time in graph order, each given a moment to hand its final messages
  // to the next before that one stops: the backend's last optimisation, then the densifier's
  // settled segments (stopped all at once, the mapper missed the densifier's last 41 messages on
  // office-x2).
  for (const std::string& name : stage_names) {
    sup.stop({name}, plan.stop_timeout_s);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  if (plan.records) {
    sup.stop({"monitor"}, o.stop_timeout_s);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // last messages reach the logger
    sup.stop({"logger"}, o.stop_timeout_s);
  }
  write_status(sup);
  fs::remove(out_dir / "lcm_url", ec_ignored);  // nothing listens there any more
  report.duration_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (plan.records && !stop_requested()) {
    for (auto& p : monitor_problems((out_dir / "monitor.json").string())) {
      report.verdict_problems.push_back(std::move(p));
    }
    for (auto& p : recorder_problems((out_dir / "logger.log").string())) {
      report.verdict_problems.push_back(std::move(p));
    }
  }
  report.events = policy.events();
  report.stopped_by = policy.stopped_by();

  const int rc = finish_report(report, sup, spawned);
  const std::string json = to_json(report);
  std::ofstream(out_dir / "run-graph.json") << json << '\n';
  std::fputs(to_text(report).c_str(), stdout);
  std::puts(json.c_str());  // the JSON line last
  std::fflush(stdout);
  return rc;
}

}  // namespace traverse::launch
