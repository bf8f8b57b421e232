// The whole simulated run: a world, a route driven by the cart, and the four sensor streams
// (ground truth, IMU, horizontal scanner, profile scanner) merged into one sequence ordered by
// message time, so that a log written from it has non-decreasing event times. Each stream draws
// from its own random generator derived from the seed, so a stream's content does not depend on
// how the streams interleave, and the same inputs and seed always give the same sequence.
// A scan is stamped (and ordered) by the time of its first beam, as planar_scan_t defines. With
// the realistic profile's clocks each stream is stamped (and ordered) by its own clock, the
// ground truth by the horizontal scanner's clock without its jitter: the time base of every pose
// the graph estimates (a scan's stamp), against which the other sensors' clocks are off.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "effects.hpp"
#include "odometry.hpp"
#include "people.hpp"
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
  Effects effects;                         // the realistic profile (--profile ideal: all off)
  template <class V>
  void visit(V& v) {
    v("rig_file", rig_file);
    v("platform", platform);
    v("start_utime", start_utime);
    v("effects", effects);
  }
};

std::optional<std::string> validate(const SimConfig& c);

// Which part of the route to simulate and how densely.
struct RunOptions {
  double begin_s = 0.0;     // [s] skip this much of the route's start
  double duration_s = 0.0;  // [s] simulate this much after begin_s; <= 0: to the route's end
  int profile_every = 1;    // keep every n-th profile of the tilted scanner (small sample logs)
};

struct GroundTruth {
  int64_t utime = 0;   // [us] on the horizontal scanner's clock (true time without clocks)
  Pose2 T_world_base;  // planar projection: x, y, yaw
  Eigen::Isometry3d T_world_base_3d = Eigen::Isometry3d::Identity();
};

struct SimEvent {
  enum class Kind { kGroundTruth, kImu, kScanHorizontal, kScanProfile, kOdometry };
  Kind kind = Kind::kGroundTruth;
  int64_t utime = 0;  // [us] message time
  GroundTruth ground_truth;
  ImuData imu;
  ScanData scan;
  OdometryData odometry;
};

// What the realistic profile drew for this run (not published: the processes are not told).
struct RunTruth {
  Extrinsic laser_horizontal, laser_profile, imu;  // true T_base_sensor
  SensorClock horizontal_clock, profile_clock, imu_clock, odometry_clock;
  std::map<std::string, double> swap_times;  // [s] movable group -> time it changes
  double start_yaw_rad = 0.0;  // [rad] the cart set down turned from its first leg (draw_start_yaw)
};

class Simulator {
 public:
  // Throws std::runtime_error on inconsistent inputs (route for another world, unknown scanner
  // model, bad geometry or options). Message times count from start_utime at the route's start.
  // `effects`: the realistic profile's effects, or (the default, as callers before the profiles
  // had it) none.
  Simulator(const WorldSpec& world, const RouteSpec& route, const RigConfig& rig,
            const PlatformConfig& platform, uint64_t seed, int64_t start_utime,
            const RunOptions& options = {}, const Effects& effects = Effects{}.ideal());
  Simulator(const Simulator&) = delete;  // the sensors hold references to the world and route
  Simulator& operator=(const Simulator&) = delete;

  // The next message in time order, or nullopt after the last one.
  std::optional<SimEvent> next();

  const World& world() const { return *world_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const RunTruth& truth() const { return truth_; }
  const People* people() const { return people_.get(); }
  const ScannerModel& horizontal_model() const { return horizontal_model_; }
  int64_t start_utime() const { return clock_.start_utime; }
  int64_t begin_utime() const { return begin_utime_; }
  int64_t end_utime() const { return end_utime_; }

 private:
  static constexpr int kStreams = 5;
  int64_t stream_utime(int s) const;  // true time of the stream's next message
  int64_t stream_stamp(int s) const;  // its stamp (the sensor's clock)

  RigConfig rig_;
  Effects effects_;
  Rng trajectory_rng_;
  Trajectory trajectory_;
  std::unique_ptr<World> world_;
  std::unique_ptr<People> people_;
  std::unique_ptr<SurfaceModel> surface_;
  RunTruth truth_;
  Clock clock_;
  ScannerModel horizontal_model_;
  std::unique_ptr<ScannerSim> horizontal_;
  std::unique_ptr<ScannerSim> profile_;
  std::unique_ptr<ImuSim> imu_;
  std::unique_ptr<OdometrySim> odometry_;
  int64_t next_index_[kStreams] = {0, 0, 0, 0, 0};
  int64_t last_stamp_[kStreams] = {0, 0, 0, 0, 0};
  int64_t begin_utime_ = 0;
  int64_t end_utime_ = 0;
  int profile_every_ = 1;
};

// The scanner model named `name` among the rig's horizontal scanners; throws if absent.
ScannerModel find_horizontal_model(const RigConfig& rig, const std::string& name);

// When each movable group changes [s]: halfway between the cart's first and second visit
// (within `radius` of the group's centre), else halfway through the route.
std::map<std::string, double> movable_swap_times(const WorldSpec& world,
                                                 const Trajectory& trajectory, double radius);

}  // namespace traverse::sim
