// traverse-backend: Karto-style backend (seed 000) with marginal covariances (seed 004).
// Subscribes to the horizontal scans and the frontend's poses; after each optimisation publishes
// the key poses that changed with their marginal covariances (KEY_POSES, incremental) and each new
// key pose once on POSE_BACKEND.
#include "backend_node.hpp"
#include "process.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("backend",
                         "Pose-graph backend: correlative matching, best-of-candidates loop "
                         "closure, SPA, marginal covariances of the key poses");
  traverse::backend::BackendNodeConfig config;
  proc.offer_replay();
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  traverse::backend::BackendNode node(
      proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; });
  const int rc = proc.spin([&node] { node.report_counters(); });
  node.finish();
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
