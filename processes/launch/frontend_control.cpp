#include "frontend_control.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>

#include "bus.hpp"
#include "channels.hpp"
#include "json.hpp"
#include "process.hpp"
#include "traverse/frontend_control_t.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse::launch {

int send_frontend_control(const std::filesystem::path& out_dir, const std::string& process,
                          const std::string& kind, double timeout_s) {
  if (kind != "hector" && kind != "icp") {
    std::fprintf(stderr, "run-graph: --control frontend: --kind must be hector or icp, got '%s'\n",
                 kind.c_str());
    return 2;
  }
  std::string url;
  std::ifstream(out_dir / "lcm_url") >> url;
  if (url.empty()) {
    std::fprintf(stderr, "run-graph: no run in progress in %s (no lcm_url there)\n",
                 out_dir.c_str());
    return 1;
  }
  Bus bus(url);
  if (!bus.good()) {
    std::fprintf(stderr, "run-graph: cannot reach the run's LCM URL %s\n", url.c_str());
    return 1;
  }
  const int64_t id = now_utime();
  std::map<std::string, double> seen;
  bool heard = false;
  bus.subscribe<process_status_t>(channels::status_channel(process),
                                  [&](const process_status_t& s) {
                                    heard = true;
                                    for (int i = 0; i < s.n_counters; ++i) {
                                      seen[s.counter_names[i]] = s.counter_values[i];
                                    }
                                  });
  const bool want_icp = kind == "icp";
  const auto done = [&] {
    return seen.count("frontend_request_id") && seen["frontend_request_id"] >= id &&
           (seen["frontend_kind_icp"] == 1.0) == want_icp;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  auto next_send = std::chrono::steady_clock::now();
  while (!done() && std::chrono::steady_clock::now() < deadline) {
    if (std::chrono::steady_clock::now() >= next_send) {
      frontend_control_t m{};
      m.utime = now_utime();
      m.request_id = id;
      m.kind = kind;
      bus.publish(channels::kFrontendControl, m);
      next_send += std::chrono::milliseconds(200);
    }
    bus.handle(50);
  }
  if (!done()) {
    if (!heard) {
      std::fprintf(stderr, "run-graph: no status from '%s' on %s within %.0f s\n", process.c_str(),
                   url.c_str(), timeout_s);
    } else {
      std::fprintf(stderr,
                   "run-graph: '%s' did not carry out the request within %.0f s: it still runs "
                   "%s\n",
                   process.c_str(), timeout_s, seen["frontend_kind_icp"] == 1.0 ? "icp" : "hector");
    }
    return 1;
  }
  Json j;
  j["process"] = process;
  j["kind"] = kind;
  j["request_id"] = static_cast<long long>(id);
  j["swaps"] = static_cast<long long>(seen["frontend_swaps"]);
  std::printf("%s\n", json_line(j).c_str());
  return 0;
}

}  // namespace traverse::launch
