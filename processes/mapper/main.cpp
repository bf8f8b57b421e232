// traverse-mapper: places every point of the tilted profile scanner with the corrected trajectory
// at its own time, into an OctoMap and a full-density cloud that follow loop closures. Exports
// cloud.ply, map.bt and map.ot into the output folder on SIGUSR1 and at shutdown.
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>

#include "mapper_node.hpp"
#include "process.hpp"
#include "rig.hpp"

namespace {
std::atomic<bool> g_export_requested{false};
void on_usr1(int) { g_export_requested = true; }
}  // namespace

int main(int argc, char** argv) {
  traverse::Process proc("mapper",
                         "3D mapper: tilted profiles -> OctoMap and point cloud that follow loop "
                         "closures; exports on SIGUSR1 and at shutdown");
  traverse::mapper::MapperConfig config;
  std::string out_dir;
  proc.cli().add_option("--out", out_dir, "export folder (overrides output_dir of the config)");
  proc.offer_replay();
  if (auto rc = proc.start(argc, argv, config)) return *rc;  // validate(config) included
  if (!out_dir.empty()) config.output_dir = out_dir;
  traverse::sim::RigConfig rig;
  try {
    traverse::load_config(config.rig_file, rig);
  } catch (const traverse::ConfigError& e) {
    spdlog::error("{} (rig_file of {})", e.what(), proc.config_path());
    return traverse::kConfigErrorExitCode;
  }
  std::signal(SIGUSR1, on_usr1);
  // Live, a worker thread does the mapping so that status and export requests are answered while
  // a loop closure's moves are applied; a replay works inline (it would otherwise queue the whole
  // log).
  traverse::mapper::MapperNode node(
      proc.bus(), config, rig.laser_profile.transform(),
      [&proc](const std::string& name, double v) { proc.counter(name) = v; }, !proc.replaying());
  auto do_export = [&node, &config] {
    std::string error;
    if (node.export_all(&error)) {
      spdlog::info("mapper: exported {} points to {}", node.mapper().placed_points(),
                   config.output_dir);
    } else {
      spdlog::error("mapper: export failed: {}", error);
    }
  };
  const int rc = proc.spin([&] {
    node.publish_preview();
    node.report_counters();
    if (g_export_requested.exchange(false)) do_export();
  });
  node.finish();
  node.publish_preview();
  do_export();
  node.report_counters();
  proc.publish_status("stopped");
  return rc;
}
