// traverse-frontend: the frontend (frontend.hpp; the Hector scan-to-map matcher as configured).
// Subscribes to planar scans and IMU samples, publishes one pose per scan (map -> base) with its
// covariance (on a log subsampled by travel, one scan late: matcher.sparse_lag).
#include "frontend_node.hpp"
#include "process.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("frontend",
                         "Hector-style scan-to-map matcher: one pose per scan with covariance");
  traverse::frontend::FrontendConfig config;
  proc.offer_replay();
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  traverse::frontend::FrontendNode node(
      proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; });
  const int rc = proc.spin([&node] { node.report_counters(); });
  node.flush(true);
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
