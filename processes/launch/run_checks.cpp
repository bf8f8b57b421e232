#include "run_checks.hpp"

#include <unistd.h>

#include <fstream>

#include "json.hpp"
#include "lcm_log.hpp"

namespace traverse::launch {

std::vector<std::string> input_log_problems(const std::string& path) {
  std::vector<std::string> out;
  try {
    LogReader reader(path);
    int64_t events = 0;
    while (reader.next()) ++events;
    for (const LogDamage& d : reader.damage()) {
      out.push_back("input log " + path + ": " + d.what + " at byte " + std::to_string(d.offset) +
                    " (" + std::to_string(d.skipped_bytes) + " bytes unreadable)");
    }
    if (events == 0) out.push_back("input log " + path + " has no readable event");
  } catch (const std::exception& e) {
    out.push_back(e.what());
  }
  return out;
}

std::vector<std::string> monitor_problems(const std::string& monitor_json) {
  std::ifstream in(monitor_json);
  if (!in) return {"no monitor summary " + monitor_json + ": the run has no verdict"};
  const Json j = Json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("ok")) {
    return {"monitor: " + monitor_json + " is not the monitor's summary: the run has no verdict"};
  }
  if (j["ok"] == true) return {};
  std::vector<std::string> out;
  for (const auto& p : j.value("problems", Json::array())) {
    if (p.is_string()) out.push_back("monitor: " + p.get<std::string>());
  }
  if (out.empty()) out.push_back("monitor: the run is not ok (see " + monitor_json + ")");
  return out;
}

std::vector<std::string> recorder_problems(const std::string& recorder_out) {
  std::ifstream in(recorder_out);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty() && line.front() == '{') last = line;
  }
  const Json j = Json::parse(last, nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("events_written")) {
    return {"run log: the recorder left no summary in " + recorder_out +
            " (it did not stop cleanly; the log reads up to its last flush)"};
  }
  std::vector<std::string> out;
  const long dropped = j.value("receive_queue_dropped", 0L);
  const long failed = j.value("write_errors", 0L);
  if (dropped > 0) {
    out.push_back("run log: the recorder's receive queue dropped " + std::to_string(dropped) +
                  " messages (the log lacks them)");
  }
  if (failed > 0) {
    out.push_back("run log: " + std::to_string(failed) + " events could not be written");
  }
  return out;
}

std::string check_rmem_max(long wanted, bool raise) {
  if (wanted <= 0) return "";
  const char* path = "/proc/sys/net/core/rmem_max";
  long current = 0;
  std::ifstream(path) >> current;
  if (current >= wanted) return "";
  const std::string limits = "net.core.rmem_max is " + std::to_string(current) +
                             " bytes, below the " + std::to_string(wanted) +
                             " the LCM URL asks for: ";
  if (!raise) {
    return limits +
           "each socket's receive buffer is capped there and bursts may be lost (counted). "
           "--raise-rmem-max sets it system-wide (as root)";
  }
  if (geteuid() != 0) return limits + "not root, cannot raise it";
  std::ofstream out(path);
  out << wanted;
  out.close();
  return "net.core.rmem_max raised system-wide from " + std::to_string(current) + " to " +
         std::to_string(wanted) + " bytes (--raise-rmem-max)" +
         (out ? "" : ": FAILED (read-only /proc/sys?)");
}

}  // namespace traverse::launch
