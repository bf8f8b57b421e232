// traverse-mapper: places every point of the tilted profile scanner with the corrected trajectory
// at its own time, into an OctoMap and a full-density cloud that follow loop closures. Exports
// cloud.ply, map.bt, map.ot and map_colour.ot into the output folder on SIGUSR1 and at shutdown.
// With --state-dir DIR it keeps what it took there and, started again on the same DIR (restarted
// after a crash, or a session resumed), rebuilds its map from it and goes on (mapper_state.hpp).
#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <optional>
#include <stdexcept>

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
  std::string state_dir;
  proc.cli()
      .add_option("--state-dir", state_dir,
                  "keep the profiles and trajectory taken here; resume from them if there are any")
      ->type_name("DIR");
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
  std::optional<traverse::mapper::MapperNode> node_storage;
  try {
    node_storage.emplace(
        proc.bus(), config, rig.laser_profile.transform(),
        [&proc](const std::string& name, double v) { proc.counter(name) = v; }, !proc.replaying(),
        state_dir);
  } catch (const std::runtime_error& e) {
    std::cerr << "traverse-mapper: cannot resume from --state-dir " << state_dir << ": " << e.what()
              << "\n";
    return 1;
  }
  traverse::mapper::MapperNode& node = *node_storage;
  if (const auto& r = node.resumed()) {
    std::cout << "traverse-mapper: resumed from " << state_dir << ": " << r->profiles
              << " profiles, " << r->segments << " trajectory segments, "
              << node.mapper().placed_points() << " points placed in " << r->seconds << " s"
              << std::endl;
  }
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
