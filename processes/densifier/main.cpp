// traverse-densifier: bends the dense frontend trajectory to the backend's optimised key poses
// (seed 000) and publishes the corrected trajectory as it grows and the segments loop closures
// move.
#include "densifier_node.hpp"
#include "process.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("densifier",
                         "Corrected dense trajectory: frontend poses bent to the optimised key "
                         "poses");
  traverse::densifier::DensifierConfig config;
  proc.offer_replay();
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  traverse::densifier::DensifierNode node(
      proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; });
  const int rc = proc.spin([&node] { node.report_counters(); });
  node.finish();
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
