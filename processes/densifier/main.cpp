// traverse-densifier: bends the dense frontend trajectory to the backend's optimised key poses
// (seed 000) and publishes the corrected trajectory as it grows and the segments loop closures
// move.
#include <spdlog/spdlog.h>

#include "densifier_node.hpp"
#include "process.hpp"

int main(int argc, char** argv) {
  traverse::Process proc("densifier",
                         "Corrected dense trajectory: frontend poses bent to the optimised key "
                         "poses");
  traverse::densifier::DensifierConfig config;
  proc.offer_replay();
  if (auto rc = proc.start(argc, argv, config)) return *rc;
  if (!traverse::densifier::parse_mode(config.mode)) {
    spdlog::error("{}: mode must be paper or rigid, not '{}'", proc.config_path(), config.mode);
    return traverse::kConfigErrorExitCode;
  }
  if (!(config.spike_threshold_m >= 0.0)) {
    spdlog::error("{}: spike_threshold_m must be >= 0 (0: never), not {}", proc.config_path(),
                  config.spike_threshold_m);
    return traverse::kConfigErrorExitCode;
  }
  if (config.spike_max_span_us < 0) {
    spdlog::error("{}: spike_max_span_us must be >= 0, not {}", proc.config_path(),
                  config.spike_max_span_us);
    return traverse::kConfigErrorExitCode;
  }
  if (config.spike_min_interval_us < 0) {
    spdlog::error("{}: spike_min_interval_us must be >= 0, not {}", proc.config_path(),
                  config.spike_min_interval_us);
    return traverse::kConfigErrorExitCode;
  }
  // Below a few kilobytes a message holds only a handful of segments and bursts grow long again.
  if (config.max_message_bytes < 4096) {
    spdlog::error("{}: max_message_bytes must be at least 4096, not {}", proc.config_path(),
                  config.max_message_bytes);
    return traverse::kConfigErrorExitCode;
  }
  traverse::densifier::DensifierNode node(
      proc.bus(), config, [&proc](const std::string& name, double v) { proc.counter(name) = v; });
  const int rc = proc.spin([&node] { node.report_counters(); });
  node.finish();
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
