// The offline run (--offline): no bus, the stages one after another on the log.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <regex>
#include <thread>

#include "launch_report.hpp"
#include "lcm_log.hpp"
#include "process.hpp"
#include "run_checks.hpp"
#include "run_modes.hpp"

namespace fs = std::filesystem;

namespace traverse::launch {
namespace {

// The intact events of `in` whose channel does not match `skip` (the whole name), renumbered.
bool copy_log_without(const fs::path& in, const fs::path& out, const std::string& skip) {
  const std::regex skipped(skip);
  LogWriter log(out.string());
  if (!log.good()) return false;
  LogReader reader(in.string());
  while (auto ev = reader.next()) {
    if (std::regex_match(ev->channel, skipped)) continue;
    if (!log.write(ev->channel, ev->data.data(), ev->data.size(), ev->utime)) return false;
  }
  return true;
}

}  // namespace

// --offline: each stage reads the previous stage's record (the first reads the input log) with
// --replay and writes its own with --record: everything the input had plus what the stage
// published. The last record becomes run.lcmlog; the ones in between are deleted as soon as the
// next stage has read them. Deterministic: the same input gives the same messages.
int run_offline(const Options& o, const Plan& plan, const fs::path& out_dir) {
  const auto& planned = plan.stages;
  const auto& monitor_argv = plan.monitor_argv;
  const auto t0 = std::chrono::steady_clock::now();
  Supervisor sup;
  std::string error;
  bool ok = true;
  fs::path input = fs::absolute(o.log);
  std::vector<std::string> names;
  for (const auto& stage : planned) {
    const std::string& name = stage.name;
    std::vector<std::string> argv = stage.argv;
    const fs::path record = out_dir / (name + ".lcmlog");
    argv.insert(argv.end(), {"--replay", input.string(), "--record", record.string()});
    std::fprintf(stderr, "run-graph: offline stage '%s' on %s\n", name.c_str(), input.c_str());
    if (!sup.spawn(name, argv, (out_dir / (name + ".log")).string(), error)) {
      std::fprintf(stderr, "run-graph: %s\n", error.c_str());
      ok = false;
      break;
    }
    names.push_back(name);
    while (sup.find(name)->running && !stop_requested()) {
      announce(sup.reap());
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (stop_requested()) break;
    if (sup.find(name)->died()) {
      ok = false;
      break;
    }
    if (input != fs::absolute(o.log)) fs::remove(input);
    input = record;
  }
  sup.stop(names, o.stop_timeout_s);
  std::error_code ec;
  if (ok && !stop_requested() && !o.record_without.empty()) {
    // The stages hand each other whole records; run.lcmlog keeps what --record-without leaves.
    if (!copy_log_without(input, out_dir / "run.lcmlog", o.record_without)) {
      ec = std::make_error_code(std::errc::io_error);
    }
    if (input != fs::absolute(o.log)) fs::remove(input);
  } else if (ok && !stop_requested() && input != fs::absolute(o.log)) {
    fs::rename(input, out_dir / "run.lcmlog", ec);
  } else if (ok && !stop_requested()) {
    fs::copy_file(input, out_dir / "run.lcmlog", fs::copy_options::overwrite_existing, ec);
  }
  RunReport report;
  report.url = "offline";
  report.out_dir = out_dir.string();
  report.verdict_problems = input_log_problems(o.log);
  if (ok && !stop_requested() && !ec) {
    // The monitor judges the recorded run: what each stage reported in its statuses.
    std::vector<std::string> argv = monitor_argv;
    argv.insert(argv.end(), {"--replay", (out_dir / "run.lcmlog").string()});
    std::fprintf(stderr, "run-graph: the monitor judges %s\n", (out_dir / "run.lcmlog").c_str());
    if (sup.spawn("monitor", argv, (out_dir / "monitor.log").string(), error)) {
      while (sup.find("monitor")->running && !stop_requested()) {
        sup.reap();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      sup.stop({"monitor"}, o.stop_timeout_s);
    }
    for (auto& p : monitor_problems((out_dir / "monitor.json").string())) {
      report.verdict_problems.push_back(std::move(p));
    }
  }
  report.interrupted = stop_requested();
  report.duration_s = report.replay_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int rc = finish_report(report, sup, ok);
  if (ec) {
    std::fprintf(stderr, "run-graph: cannot write %s: %s\n", (out_dir / "run.lcmlog").c_str(),
                 ec.message().c_str());
    rc = 1;
  }
  const std::string json = to_json(report);
  std::ofstream(out_dir / "run-graph.json") << json << '\n';
  std::fputs(to_text(report).c_str(), stdout);
  std::puts(json.c_str());
  std::fflush(stdout);
  return rc;
}

}  // namespace traverse::launch
