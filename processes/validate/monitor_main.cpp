// traverse-monitor: listens to every channel of a running graph and, when stopped (SIGINT or
// SIGTERM), prints and writes (--out FILE) a JSON summary: per channel the checks of
// traverse-validate, per process its last status and whether it went silent or stalled, and the
// verdict against the thresholds of its config (configs/monitor.yaml). With --replay it judges a
// recorded run the same way, without the checks of time. Exits 0 unless LCM failed or the summary
// could not be written; the summary's "ok" tells whether the run was clean.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "monitor_node.hpp"
#include "process.hpp"

namespace {

// Writes `text` to `path` through a temporary file, so a reader never sees half a summary.
bool write_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text << '\n';
    if (!out.flush()) return false;
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  return !ec;
}

}  // namespace

int main(int argc, char** argv) {
  traverse::Process proc("monitor",
                         "Listens to every LCM channel and to every process's status; at "
                         "SIGINT/SIGTERM prints and writes a JSON summary of the run.");
  traverse::MonitorConfig cfg;
  std::string out_path;
  proc.cli().add_option("--out", out_path, "JSON summary written at shutdown");
  proc.offer_replay();  // judges a recorded run (offline): no status gaps nor silence
  if (auto rc = proc.start(argc, argv, cfg)) return *rc;

  traverse::MonitorNode node(proc.bus(), cfg, proc.name(), !proc.replaying());
  int rc = proc.spin([&] { proc.counter("events") = static_cast<double>(node.events()); });

  const auto summary = node.summary(traverse::now_utime());
  const std::string json = traverse::validate::to_json(summary);
  std::fputs(traverse::validate::to_text(summary).c_str(), stdout);
  std::puts(json.c_str());
  std::fflush(stdout);
  if (!out_path.empty() && !write_atomically(out_path, json)) {
    spdlog::error("traverse-monitor: cannot write {}", out_path);
    rc = 1;
  }
  return rc;
}
