#include "launch_report.hpp"

#include <cstdio>
#include <filesystem>

#include "json_escape.hpp"

namespace traverse::launch {
namespace {

std::string quoted(const std::string& s) {
  std::string out = "\"";
  out += json_escape(s);
  out += '"';
  return out;
}

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

std::string to_text(const RunReport& report) {
  std::string s = "run-graph: " + report.url + ", replay " + number(report.replay_s) +
                  " s, whole run " + number(report.duration_s) + " s" +
                  (report.interrupted ? ", INTERRUPTED" : "") + "\n";
  for (const auto& c : report.children) {
    char line[256];
    std::snprintf(line, sizeof(line), "  %-12s %-22s %s%s%s\n", c.name.c_str(), c.program.c_str(),
                  c.outcome.c_str(), c.failed ? "  <-- " : "", c.failed ? c.why.c_str() : "");
    s += line;
  }
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
  std::string j =
      "{\"ok\":" + std::string(report.ok ? "true" : "false") + ",\"url\":" + quoted(report.url) +
      ",\"out\":" + quoted(report.out_dir) + ",\"replay_s\":" + number(report.replay_s) +
      ",\"duration_s\":" + number(report.duration_s) +
      ",\"interrupted\":" + (report.interrupted ? "true" : "false") + ",\"processes\":[";
  for (std::size_t i = 0; i < report.children.size(); ++i) {
    const auto& c = report.children[i];
    if (i) j += ',';
    j += "{\"name\":" + quoted(c.name) + ",\"program\":" + quoted(c.program) +
         ",\"outcome\":" + quoted(c.outcome) + ",\"exit_code\":" + std::to_string(c.exit_code) +
         ",\"signal\":" + std::to_string(c.signal) +
         ",\"failed\":" + (c.failed ? "true" : "false") + "}";
  }
  j += "],\"failed\":[";
  for (std::size_t i = 0; i < report.failed.size(); ++i) {
    if (i) j += ',';
    j += quoted(report.failed[i]);
  }
  j += "],\"problems\":[";
  for (std::size_t k = 0; k < report.verdict_problems.size(); ++k) {
    if (k) j += ',';
    j += quoted(report.verdict_problems[k]);
  }
  j += "],\"not_ready\":[";
  std::size_t i = 0;
  for (const auto& n : report.not_ready) {
    if (i++) j += ',';
    j += quoted(n);
  }
  return j + "]}";
}

}  // namespace traverse::launch
