// traverse-backend: Karto-style backend (seed 000) with marginal covariances (seed 004).
// Subscribes to the horizontal scans and the frontend's poses; after each optimisation publishes
// the key poses that changed with their marginal covariances (KEY_POSES, incremental) and each new
// key pose once on POSE_BACKEND. With --state-dir DIR it keeps its graph and key scans there and,
// started again on the same DIR (restarted after a crash, or a session resumed), goes on from them
// (backend_state.hpp).
#include <iostream>
#include <stdexcept>

#include "backend_node.hpp"
#include "process.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("backend",
                         "Pose-graph backend: correlative matching, best-of-candidates loop "
                         "closure, SPA, marginal covariances of the key poses");
  traverse::backend::BackendNodeConfig config;
  proc.offer_replay();
  std::string state_dir;
  proc.cli()
      .add_option("--state-dir", state_dir,
                  "keep the graph and key scans here; resume from them if there are any")
      ->type_name("DIR");
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  std::optional<traverse::backend::BackendNode> node_storage;
  try {
    node_storage.emplace(
        proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; },
        state_dir);
  } catch (const std::runtime_error& e) {
    std::cerr << "traverse-backend: cannot resume from --state-dir " << state_dir << ": "
              << e.what() << "\n";
    return 1;
  }
  traverse::backend::BackendNode& node = *node_storage;
  if (const auto& r = node.resumed()) {
    std::cout << "traverse-backend: resumed from " << state_dir << ": " << r->key_poses
              << " key poses, " << r->closures << " loop closures, the last at "
              << static_cast<double>(r->last_key_utime) * 1e-6 << " s" << std::endl;
  }
  const int rc = proc.spin([&node] { node.report_counters(); });
  node.finish();
  node.report_counters();
  if (const std::string fault = node.backend().input_fault(); !fault.empty()) {
    std::cerr << "traverse-backend: " << fault << "\n";
    proc.publish_status("failed: " + fault);
    return rc != 0 ? rc : traverse::backend::kNoTrajectoryExitCode;
  }
  proc.publish_status("stopped");
  return rc;
}
