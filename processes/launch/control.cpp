#include "control.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include "json.hpp"

namespace fs = std::filesystem;

namespace traverse::launch {
namespace {

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return "";
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// True when processes.json (as the launcher writes it) lists a running process.
bool any_running(const std::string& processes_json) {
  const Json j = Json::parse(processes_json, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  for (const auto& p : j.value("processes", Json::array())) {
    if (p.is_object() && p.value("running", false)) return true;
  }
  return false;
}

}  // namespace

std::optional<ControlRequest> take_control_request(const fs::path& out_dir) {
  const fs::path path = out_dir / "control";
  std::ifstream in(path);
  if (!in) return std::nullopt;
  ControlRequest r;
  in >> r.command >> r.name;
  return r;
}

void done_control_request(const fs::path& out_dir) {
  std::error_code ec;
  fs::remove(out_dir / "control", ec);
}

std::string apply_control(const ControlRequest& r, Supervisor& sup, double stop_timeout_s) {
  const Child* c = sup.find(r.name);
  const std::string what = r.command + " " + r.name;
  if (!c) return what + ": no such process here";
  std::string error;
  if (r.command == "stop" || r.command == "restart") {
    sup.stop({r.name}, stop_timeout_s);
    if (r.command == "stop") return what + ": " + sup.find(r.name)->outcome();
  } else if (r.command != "start") {
    return what + ": unknown command";
  }
  if (sup.find(r.name)->running) return what + ": already running";
  if (!sup.respawn(r.name, error)) return what + ": " + error;
  return what + ": running (pid " + std::to_string(sup.find(r.name)->pid) + ")";
}

int send_control(const fs::path& out_dir, const std::string& command, const std::string& name,
                 double timeout_s) {
  const fs::path status = out_dir / "processes.json";
  if (command != "status") {
    if (command != "start" && command != "stop" && command != "restart") {
      std::fprintf(stderr,
                   "run-graph: --control: unknown command '%s' (start, stop, restart, "
                   "status)\n",
                   command.c_str());
      return 2;
    }
    if (name.empty()) {
      std::fprintf(stderr, "run-graph: --control %s needs --process NAME\n", command.c_str());
      return 2;
    }
    if (!any_running(read_file(status))) {
      std::fprintf(stderr, "run-graph: no run in progress in %s (%s shows nothing running)\n",
                   out_dir.c_str(), status.c_str());
      return 1;
    }
    const fs::path tmp = out_dir / "control.tmp", request = out_dir / "control";
    std::ofstream(tmp) << command << ' ' << name << '\n';
    std::error_code ec;
    fs::rename(tmp, request, ec);
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (fs::exists(request) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (fs::exists(request)) {
      fs::remove(request, ec);
      std::fprintf(stderr, "run-graph: no launcher took the request in %s within %.0f s\n",
                   out_dir.c_str(), timeout_s);
      return 1;
    }
  }
  const std::string text = read_file(status);
  if (text.empty()) {
    std::fprintf(stderr, "run-graph: no %s: no launcher writes there\n", status.c_str());
    return 1;
  }
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace traverse::launch
