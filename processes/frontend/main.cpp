// traverse-frontend: the frontend (frontend.hpp: the Hector scan-to-map matcher or point-to-line
// ICP, config `kind`). Subscribes to planar scans, IMU and odometry samples, publishes one pose
// per scan (map -> base) with its covariance (on a log subsampled by travel, one scan late:
// matcher.sparse_lag). A frontend_control_t on FRONTEND_CONTROL hands over to another kind while
// it runs. With --state-dir DIR it saves its recent scans there and, started again on DIR, goes
// on from them (a session resumed, or a restart after a crash), checking its first scans against
// them: exit 4 when they do not fit (frontend_node.hpp).
#include <iostream>
#include <optional>
#include <stdexcept>

#include "frontend_node.hpp"
#include "process.hpp"

namespace {
constexpr int kResumeMismatchExitCode = 4;
}

int main(int argc, char** argv) {
  traverse::Process proc("frontend",
                         "Scan matcher (Hector or ICP): one pose per scan with covariance");
  traverse::frontend::FrontendConfig config;
  proc.offer_replay();
  std::string state_dir;
  proc.cli()
      .add_option("--state-dir", state_dir,
                  "keep the recent scans here; resume from them if there are any")
      ->type_name("DIR");
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  std::optional<traverse::frontend::FrontendNode> storage;
  try {
    storage.emplace(
        proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; },
        state_dir);
  } catch (const std::runtime_error& e) {
    std::cerr << "traverse-frontend: cannot resume from --state-dir " << state_dir << ": "
              << e.what() << "\n";
    return 1;
  }
  traverse::frontend::FrontendNode& node = *storage;
  if (const auto scans = node.resumed_scans()) {
    std::cout << "traverse-frontend: resumed from " << state_dir << " (" << node.kind() << ", "
              << *scans << " saved scans re-tracked)" << std::endl;
  }
  const int rc = proc.spin([&node] { node.report_counters(); },
                           [&node] { return !node.resume_failure().empty(); });
  node.flush(true);
  node.report_counters();
  if (!node.resume_failure().empty()) {
    std::cerr << "traverse-frontend: " << node.resume_failure() << "\n";
    proc.publish_status("failed: " + node.resume_failure());
    return kResumeMismatchExitCode;
  }
  node.save_state();
  proc.publish_status("stopped");
  return rc;
}
