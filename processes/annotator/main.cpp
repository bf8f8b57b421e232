// traverse-annotator: 95 % bounds on every key pose's position error, the surveying accuracy level
// they fall in and a colour (seed 004, with the 2D quantile, a calibrated covariance scale and a
// local view). Subscribes to the backend's POSE_GRAPH_EDGES and KEY_POSES; publishes ANNOTATIONS.
#include "annotator_node.hpp"
#include "process.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("annotator",
                         "Uncertainty annotator: calibrated 95 % bounds on the key poses, turned "
                         "into the accuracy levels of a surveying standard and colours");
  traverse::annotator::AnnotatorNodeConfig config;
  proc.offer_replay();
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  traverse::annotator::AnnotatorNode node(
      proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; });
  const int rc = proc.spin([&node] { node.report_counters(); });
  node.finish();
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
