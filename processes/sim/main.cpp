// traverse-sim: simulated mobile laser scanner. Drives the cart along a route through a world and
// publishes the horizontal scans, tilted profiles, IMU samples and ground-truth poses (and, with
// wheel encoders, odometry), either live at the sensors' pace (times --speed) or as an LCM log
// (--out), which is byte-identical for the same inputs, profile and seed. --profile realistic
// (the default) applies the effects of the config's `effects:`; --profile ideal none of them.
#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <thread>

#include "json.hpp"
#include "process.hpp"
#include "sim_node.hpp"

namespace {

// The log mode never touches the network: know it before Process::start connects.
bool has_out_option(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--out") == 0 || std::strncmp(argv[i], "--out=", 6) == 0) return true;
  return false;
}

const char* channel_of(traverse::sim::SimEvent::Kind kind) {
  using K = traverse::sim::SimEvent::Kind;
  switch (kind) {
    case K::kGroundTruth:
      return "ground_truth";
    case K::kImu:
      return "imu";
    case K::kScanHorizontal:
      return "scans_horizontal";
    case K::kOdometry:
      return "odometry";
    default:
      return "scans_profile";
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace traverse;
  Process proc("sim",
               "Simulated mobile laser scanner: horizontal scanner, tilted profile scanner, "
               "IMU and ground truth from a world and a route");
  std::string world_path, route_path, out_path;
  uint64_t seed = 0;
  double speed = 1.0;
  sim::RunOptions run;
  std::string profile = "realistic";
  bool wheel_encoders = false;
  auto& cli = proc.cli();
  cli.add_option("--profile", profile,
                 "realistic: the effects of the config's 'effects:' (3D cart, clocks, calibration, "
                 "people, per-beam errors...); ideal: none of them")
      ->check(CLI::IsMember({"ideal", "realistic"}))
      ->capture_default_str();
  cli.add_flag("--wheel-encoders", wheel_encoders,
               "publish wheel odometry on ODOMETRY (as effects.wheel_encoders.enabled: true)");
  cli.add_option("--world", world_path, "world YAML (configs/worlds/)")->required();
  cli.add_option("--route", route_path, "route YAML (configs/routes/)")->required();
  cli.add_option("--seed", seed, "random seed (same inputs and seed give the same log)")
      ->capture_default_str();
  cli.add_option("--duration", run.duration_s,
                 "[s] stop after this much simulated time (0: whole route)")
      ->capture_default_str();
  cli.add_option("--begin", run.begin_s, "[s] skip this much of the route's start")
      ->capture_default_str();
  cli.add_option("--profile-every", run.profile_every,
                 "keep every n-th profile of the tilted scanner (small sample logs)")
      ->capture_default_str();
  auto* out_opt = cli.add_option("--out", out_path, "write an LCM log here instead of publishing");
  cli.add_option("--speed", speed, "live pace relative to real time (0: as fast as possible)")
      ->capture_default_str()
      ->excludes(out_opt);

  sim::SimConfig cfg;
  // validate(cfg) included.
  if (auto rc = proc.start(argc, argv, cfg, !has_out_option(argc, argv))) return *rc;
  if (wheel_encoders) cfg.effects.wheel_encoders.enabled = true;
  const bool realistic = profile == "realistic";
  const sim::Effects effects = realistic ? cfg.effects : cfg.effects.ideal();

  std::unique_ptr<sim::Simulator> simulator;
  sim::RigConfig rig;  // the rig file, against which the run's true extrinsics are reported
  try {
    if (!cfg.rig_file.empty()) load_config(cfg.rig_file, rig);
    sim::WorldSpec world;
    load_config(world_path, world);
    sim::RouteSpec route;
    load_config(route_path, route);
    simulator = std::make_unique<sim::Simulator>(world, route, rig, cfg.platform, seed,
                                                 cfg.start_utime, run, effects);
  } catch (const ConfigError& e) {
    spdlog::error("traverse-sim: {}", e.what());
    return kConfigErrorExitCode;
  } catch (const std::exception& e) {
    spdlog::error("traverse-sim: bad world or route: {}", e.what());
    return kConfigErrorExitCode;
  }

  std::unique_ptr<LogFilePublisher> log;
  if (!out_path.empty()) {
    try {
      log = std::make_unique<LogFilePublisher>(out_path);
    } catch (const std::exception& e) {
      spdlog::error("traverse-sim: {}", e.what());
      return 1;
    }
  }
  Publisher& publisher = log ? static_cast<Publisher&>(*log) : proc.bus();
  if (!log) proc.publish_status("running");

  const auto wall_start = std::chrono::steady_clock::now();
  std::map<std::string, int64_t> counts;
  int rc = 0;
  int64_t last_utime = simulator->begin_utime();
  while (!stop_requested()) {
    auto ev = simulator->next();
    if (!ev) break;
    if (!log && speed > 0.0) {
      // Live: publish each message when its time has come, scaled by --speed.
      const auto due = wall_start + std::chrono::microseconds(static_cast<int64_t>(
                                        (ev->utime - simulator->begin_utime()) / speed));
      while (!stop_requested() && std::chrono::steady_clock::now() < due) {
        std::this_thread::sleep_until(
            std::min(due, std::chrono::steady_clock::now() + std::chrono::milliseconds(100)));
        proc.maybe_publish_status();
      }
      if (stop_requested()) break;
    }
    try {
      sim::publish_event(publisher, *ev, realistic);
    } catch (const std::exception& e) {
      spdlog::error("traverse-sim: {}", e.what());
      rc = 1;
      break;
    }
    ++counts[channel_of(ev->kind)];
    last_utime = ev->utime;
    if (!log) {
      proc.counter(std::string(channel_of(ev->kind))) += 1;
      proc.maybe_publish_status();
    }
  }
  if (!log) proc.publish_status("stopping");

  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const double sim_s = 1e-6 * static_cast<double>(last_utime - simulator->begin_utime());
  // Human summary on stderr; stdout carries only the JSON line.
  std::fprintf(stderr,
               "traverse-sim: %.1f s simulated in %.2f s wall time (%.2fx real time), route %.1f m "
               "long, %.1f s\n",
               sim_s, wall_s, sim_s / std::max(wall_s, 1e-9), simulator->trajectory().length_m(),
               simulator->trajectory().duration_s());
  traverse::Json json;
  for (const auto& [k, v] : counts) json[k] = v;
  json["profile"] = profile;
  json["sim_duration_s"] = traverse::json_fixed(sim_s, 3);
  json["wall_s"] = traverse::json_fixed(wall_s, 3);
  json["real_time_factor"] = traverse::json_fixed(sim_s / std::max(wall_s, 1e-9), 3);
  json["route_length_m"] = traverse::json_fixed(simulator->trajectory().length_m(), 2);
  json["route_duration_s"] = traverse::json_fixed(simulator->trajectory().duration_s(), 2);
  // What the realistic profile drew for this run, for analyses that need the truth (the processes
  // are never told): each sensor clock's offset [ms] and drift [ppm] (stamp = true time + offset +
  // drift x time since the start + jitter), and each sensor's extrinsic error against the rig file.
  const sim::RunTruth& truth = simulator->truth();
  const auto clock_json = [](const sim::SensorClock& c) {
    traverse::Json j;
    j["offset_ms"] = traverse::json_fixed(1e3 * c.offset_s, 4);
    j["drift_ppm"] = traverse::json_fixed(1e6 * c.drift, 3);
    return j;
  };
  json["true_clocks"]["laser_horizontal"] = clock_json(truth.horizontal_clock);
  json["true_clocks"]["laser_profile"] = clock_json(truth.profile_clock);
  json["true_clocks"]["imu"] = clock_json(truth.imu_clock);
  json["true_clocks"]["odometry"] = clock_json(truth.odometry_clock);
  // T_base_sensor as drawn, against the rig file's: yaw [rad] (the horizontal scanner's is the
  // boresight error the backend estimates), lever arm x, y [m].
  const auto extrinsic_json = [](const sim::Extrinsic& t, const sim::Extrinsic& nominal) {
    traverse::Json j;
    j["yaw_error_rad"] = traverse::json_fixed(t.yaw - nominal.yaw, 6);
    j["x_error_m"] = traverse::json_fixed(t.x - nominal.x, 4);
    j["y_error_m"] = traverse::json_fixed(t.y - nominal.y, 4);
    return j;
  };
  json["true_extrinsics"]["laser_horizontal"] =
      extrinsic_json(truth.laser_horizontal, rig.laser_horizontal);
  json["true_start_yaw_rad"] = traverse::json_fixed(truth.start_yaw_rad, 6);
  std::printf("%s\n", traverse::json_line(json).c_str());
  return rc;
}
