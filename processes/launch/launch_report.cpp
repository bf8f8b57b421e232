#include "launch_report.hpp"

#include <cstdio>
#include <filesystem>

#include "json.hpp"

namespace traverse::launch {
namespace {

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f", v);
  return buf;
}

}  // namespace

int finish_report(RunReport& report, const Supervisor& sup, bool all_started) {
  for (const Child& c : sup.children()) {
    ChildReport r;
    r.name = c.name;
    r.program = std::filesystem::path(c.argv.at(0)).filename().string();
    r.host = c.host;
    r.restarts = c.restarts;
    r.outcome = c.outcome();
    r.exit_code = c.exit_code;
    r.signal = c.term_signal;
    // Live, the logger and the monitor run until stopped; offline the monitor ends on its own.
    const bool infrastructure =
        c.name == "logger" || (c.name == "monitor" && report.url != "offline");
    if (c.died()) {
      r.failed = true;
      r.why = c.asked_to_stop ? "failed while stopping" : "died";
    } else if (c.last_signal_sent == "SIGKILL") {
      r.failed = true;
      r.why = "had to be killed";
    } else if (infrastructure && !c.asked_to_stop) {
      r.failed = true;
      r.why = "ended early";
    }
    if (r.failed) report.failed.push_back(c.name);
    report.children.push_back(std::move(r));
  }
  if (!all_started) report.failed.push_back("(launcher: a process could not be started)");
  report.ok = report.failed.empty() && report.verdict_problems.empty() && !report.interrupted;
  if (!report.failed.empty()) return 1;
  if (report.interrupted) return 130;
  return report.verdict_problems.empty() ? 0 : kVerdictFailedExitCode;
}

std::string processes_json(const Supervisor& sup) {
  Json j;
  j["processes"] = Json::array();
  for (const Child& c : sup.children()) {
    Json p;
    p["name"] = c.name;
    p["host"] = c.host;
    p["pid"] = c.pid;
    p["running"] = c.running;
    p["restarts"] = c.restarts;
    p["outcome"] = c.outcome();
    j["processes"].push_back(std::move(p));
  }
  return json_line(j);
}

std::string to_text(const RunReport& report) {
  std::string s = "run-graph: " + report.url + ", replay " + number(report.replay_s) +
                  " s, whole run " + number(report.duration_s) + " s" +
                  (report.interrupted ? ", INTERRUPTED" : "") + "\n";
  for (const auto& c : report.children) {
    char line[256];
    const std::string restarts =
        c.restarts ? ", restarted " + std::to_string(c.restarts) + " time(s)" : "";
    std::snprintf(line, sizeof(line), "  %-12s %-8s %-22s %s%s%s%s\n", c.name.c_str(),
                  c.host.empty() ? "-" : c.host.c_str(), c.program.c_str(), c.outcome.c_str(),
                  restarts.c_str(), c.failed ? "  <-- " : "", c.failed ? c.why.c_str() : "");
    s += line;
  }
  for (const auto& e : report.events) s += "  event: " + e + "\n";
  if (!report.stopped_by.empty())
    s += "  the graph was stopped: '" + report.stopped_by + "' died\n";
  for (const auto& n : report.not_ready) s += "  no status before replay from: " + n + "\n";
  for (const auto& p : report.verdict_problems) s += "  VERDICT: " + p + "\n";
  s += report.failed.empty()
           ? (report.interrupted ? "  interrupted; every process stopped cleanly\n"
                                 : "  all processes ran to the end\n")
           : "  FAILED: " + std::to_string(report.failed.size()) + " process(es), logs in " +
                 report.out_dir + "\n";
  return s;
}

std::string to_json(const RunReport& report) {
  Json j;
  j["ok"] = report.ok;
  j["url"] = report.url;
  j["out"] = report.out_dir;
  j["replay_s"] = json_fixed(report.replay_s, 3);
  j["duration_s"] = json_fixed(report.duration_s, 3);
  j["interrupted"] = report.interrupted;
  j["processes"] = Json::array();
  for (const auto& c : report.children) {
    Json p;
    p["name"] = c.name;
    p["host"] = c.host;
    p["program"] = c.program;
    p["restarts"] = c.restarts;
    p["outcome"] = c.outcome;
    p["exit_code"] = c.exit_code;
    p["signal"] = c.signal;
    p["failed"] = c.failed;
    j["processes"].push_back(std::move(p));
  }
  j["failed"] = report.failed;
  j["problems"] = report.verdict_problems;
  j["events"] = report.events;
  j["stopped_by"] = report.stopped_by;
  j["not_ready"] = report.not_ready;
  return json_line(j);
}

}  // namespace traverse::launch
