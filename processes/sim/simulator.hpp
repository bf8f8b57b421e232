// The whole simulated run: a world, a route driven by the cart, and the four sensor streams
// (ground truth, IMU, horizontal scanner, profile scanner) merged into one sequence ordered by
// message time, so that a log written from it has non-decreasing event times. Each stream draws
// from its own random generator derived from the seed, so a stream's content does not depend on
// how the streams interleave, and the same inputs and seed always give the same sequence.
// A scan is stamped (and ordered) by the time of its first beam, as planar_scan_t defines.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "rig.hpp"
#include "sensors.hpp"
#include "trajectory.hpp"
#include "world.hpp"

namespace traverse::sim {

// configs/sim.yaml: the simulator process's own settings.
struct SimConfig {
  std::string rig_file;  // rig YAML (configs/rig.yaml); empty = built-in defaults (the same values)
  PlatformConfig platform;
  int64_t start_utime = 1700000000000000;  // [us] time of the first message (fixed: logs repeat)
  template <class V>
  void visit(V& v) {
    v("rig_file", rig_file);
    v("platform", platform);
    v("start_utime", start_utime);
  }
};

// Which part of the route to simulate and how densely.
struct RunOptions {
  double begin_s = 0.0;     // [s] skip this much of the route's start
  double duration_s = 0.0;  // [s] simulate this much after begin_s; <= 0: to the route's end
  int profile_every = 1;    // keep every n-th profile of the tilted scanner (small sample logs)
};

struct GroundTruth {
  int64_t utime = 0;
  Pose2 T_world_base;
};

struct SimEvent {
  enum class Kind { kGroundTruth, kImu, kScanHorizontal, kScanProfile };
  Kind kind = Kind::kGroundTruth;
  int64_t utime = 0;  // [us] message time
  GroundTruth ground_truth;
  ImuData imu;
  ScanData scan;
};

class Simulator {
 public:
  // Throws std::runtime_error on inconsistent inputs (route for another world, unknown scanner
  // model, bad geometry or options). Message times count from start_utime at the route's start.
  Simulator(const WorldSpec& world, const RouteSpec& route, const RigConfig& rig,
            const PlatformConfig& platform, uint64_t seed, int64_t start_utime,
            const RunOptions& options = {});
  Simulator(const Simulator&) = delete;  // the sensors hold references to the world and route
  Simulator& operator=(const Simulator&) = delete;

  // The next message in time order, or nullopt after the last one.
  std::optional<SimEvent> next();

  const World& world() const { return world_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const ScannerModel& horizontal_model() const { return horizontal_model_; }
  int64_t start_utime() const { return clock_.start_utime; }
  int64_t begin_utime() const { return begin_utime_; }
  int64_t end_utime() const { return end_utime_; }

 private:
  static constexpr int kStreams = 4;
  int64_t stream_utime(int s) const;

  RigConfig rig_;
  World world_;
  Rng trajectory_rng_;
  Trajectory trajectory_;
  Clock clock_;
  ScannerModel horizontal_model_;
  ScannerSim horizontal_;
  ScannerSim profile_;
  ImuSim imu_;
  int64_t next_index_[kStreams] = {0, 0, 0, 0};
  int64_t begin_utime_ = 0;
  int64_t end_utime_ = 0;
  int profile_every_ = 1;
};

// The scanner model named `name` among the rig's horizontal scanners; throws if absent.
ScannerModel find_horizontal_model(const RigConfig& rig, const std::string& name);

}  // namespace traverse::sim
