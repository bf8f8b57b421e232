#include "run_checks.hpp"

#include <unistd.h>

#include <fstream>
#include <sstream>

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
  std::stringstream text;
  text << in.rdbuf();
  const std::string json = text.str();
  if (!in) return {"no monitor summary " + monitor_json + ": the run has no verdict"};
  if (json.find("\"ok\":true}") != std::string::npos) return {};
  std::vector<std::string> out;
  // The problems array: strings as the JSON writer escapes them (no '"' left unescaped).
  const std::string key = "\"problems\":[";
  auto at = json.find(key);
  if (at != std::string::npos) {
    at += key.size();
    while (at < json.size() && json[at] == '"') {
      std::string problem;
      for (++at; at < json.size() && json[at] != '"'; ++at) {
        if (json[at] == '\\' && at + 1 < json.size()) ++at;
        problem += json[at];
      }
      out.push_back("monitor: " + problem);
      at += json.compare(at, 2, "\",") == 0 ? 2 : 1;
    }
  }
  if (out.empty()) out.push_back("monitor: the run is not ok (see " + monitor_json + ")");
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
