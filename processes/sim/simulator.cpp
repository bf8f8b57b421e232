#include "simulator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "config.hpp"

namespace traverse::sim {
namespace {

// Independent random streams derived from the seed.
enum Stream : uint64_t {
  kTrajectoryStream = 0,
  kHorizontalStream = 1,
  kProfileStream = 2,
  kImuStream = 3,
  kCalibrationStream = 4,
  kHorizontalClock = 5,
  kProfileClock = 6,
  kImuClock = 7,
  kOdometryClock = 8,
  kPeopleStream = 9,
  kSurfaceStream = 10,
  kFloorStream = 11,
  kHorizontalEffects = 12,
  kProfileEffects = 13,
  kOdometryStream = 14,
  kStartYawStream = 15
};

// A distinct seed per stream for generators that take a seed and key their own draws.
uint64_t stream_seed(uint64_t seed, uint64_t stream) { return Rng(seed, stream).next_u64(); }

const RouteSpec& checked(const RouteSpec& route, const WorldSpec& world) {
  if (route.world != world.name)
    throw std::runtime_error("route is for world '" + route.world + "' but the world file is '" +
                             world.name + "'");
  return route;
}

}  // namespace

ScannerModel find_horizontal_model(const RigConfig& rig, const std::string& name) {
  for (const auto& m : rig.horizontal_scanners)
    if (m.name == name) return m;
  throw std::runtime_error("rig has no horizontal scanner model '" + name + "'");
}

std::map<std::string, double> movable_swap_times(const WorldSpec& world,
                                                 const Trajectory& trajectory, double radius) {
  std::map<std::string, Eigen::Vector2d> centre;
  std::map<std::string, int> count;
  for (const auto& m : world.movables) {
    centre.try_emplace(m.id, Eigen::Vector2d::Zero());
    centre[m.id] += Eigen::Vector2d(m.box.x, m.box.y);
    ++count[m.id];
  }
  std::map<std::string, double> out;
  const double end = trajectory.duration_s();
  for (auto& [id, c] : centre) {
    c /= count[id];
    // Visits: maximal stretches of time the cart is within `radius`.
    std::vector<std::pair<double, double>> visits;
    bool inside = false;
    for (double t = 0.0; t <= end; t += 0.5) {
      const bool now = (trajectory.nominal_pose(t).translation() - c).norm() < radius;
      if (now && !inside) visits.push_back({t, t});
      if (now) visits.back().second = t;
      inside = now;
    }
    out[id] = visits.size() >= 2 ? 0.5 * (visits[0].second + visits[1].first) : 0.5 * end;
  }
  return out;
}

std::optional<std::string> validate(const SimConfig& c) {
  ConfigCheck check;
  check.nested("effects", validate(c.effects));
  check.in_range("platform.accel_mps2", c.platform.accel_mps2, 0.01, 5.0);
  check.in_range("platform.yaw_rate_radps", c.platform.yaw_rate_radps, 0.01, 5.0);
  check.in_range("platform.yaw_accel_radps2", c.platform.yaw_accel_radps2, 0.01, 10.0);
  check.in_range("platform.half_track_m", c.platform.half_track_m, 0.05, 2.0);
  check.positive("platform.vibration_ref_speed_mps", c.platform.vibration_ref_speed_mps);
  for (std::size_t i = 0; i < c.platform.vibration.size(); ++i) {
    const VibrationSpec& vib = c.platform.vibration[i];
    const std::string key = "platform.vibration[" + std::to_string(i) + "].";
    check.require(vib.axis == "x" || vib.axis == "y" || vib.axis == "yaw", key + "axis",
                  "must be x, y or yaw, got '" + vib.axis + "'");
    check.positive(key + "wavelength_m", vib.wavelength_m);
  }
  return check.problem();
}

Simulator::Simulator(const WorldSpec& world, const RouteSpec& route, const RigConfig& rig,
                     const PlatformConfig& platform, uint64_t seed, int64_t start_utime,
                     const RunOptions& options, const Effects& effects)
    : rig_(rig),
      effects_(effects),
      trajectory_rng_(seed, kTrajectoryStream),
      trajectory_(checked(route, world), platform, trajectory_rng_, effects,
                  draw_start_yaw(effects.motion, Rng(seed, kStartYawStream))),
      clock_{start_utime},
      horizontal_model_(find_horizontal_model(rig, route.horizontal_scanner)) {
  if (rig.ground_truth_rate_hz <= 0 || rig.imu_model.rate_hz <= 0)
    throw std::runtime_error("rig rates must be > 0");
  if (options.begin_s < 0.0 || options.profile_every < 1)
    throw std::runtime_error("begin must be >= 0 s and profile decimation >= 1");
  // The world with the profile's layers, and movables that change between passes.
  WorldOptions wopt;
  wopt.layers = effects.world_layers;
  if (effects.world_changes.enabled) {
    truth_.swap_times =
        movable_swap_times(world, trajectory_, effects.world_changes.visit_radius_m);
    wopt.swap_times = truth_.swap_times;
  }
  world_ = std::make_unique<World>(world, 0.5, wopt);
  if (effects.floor.enabled)
    trajectory_.set_floor(std::make_shared<FloorModel>(
        world.floor, effects.floor, platform.half_track_m, stream_seed(seed, kFloorStream)));
  if (effects.people.enabled)
    people_ =
        std::make_unique<People>(effects.people, *world_, trajectory_, Rng(seed, kPeopleStream));
  if (effects.beams.surface.enabled)
    surface_ =
        std::make_unique<SurfaceModel>(effects.beams.surface, stream_seed(seed, kSurfaceStream));
  truth_.start_yaw_rad = trajectory_.start_yaw_rad();
  // This run's true extrinsics and clocks.
  Rng calib(seed, kCalibrationStream);
  truth_.laser_horizontal = perturb_extrinsic(rig.laser_horizontal, effects.calibration, calib);
  truth_.laser_profile = perturb_extrinsic(rig.laser_profile, effects.calibration, calib);
  truth_.imu = perturb_extrinsic(rig.imu, effects.calibration, calib);
  truth_.horizontal_clock = SensorClock::draw(effects.clocks, seed, kHorizontalClock);
  truth_.profile_clock = SensorClock::draw(effects.clocks, seed, kProfileClock);
  truth_.imu_clock = SensorClock::draw(effects.clocks, seed, kImuClock);
  truth_.odometry_clock = SensorClock::draw(effects.clocks, seed, kOdometryClock);
  ScanExtras extras;
  extras.beams = effects.beams;
  extras.three_d = effects.floor.enabled;
  extras.people = people_.get();
  extras.surface = surface_.get();
  extras.clock = truth_.horizontal_clock;
  extras.effects_seed = stream_seed(seed, kHorizontalEffects);
  horizontal_ = std::make_unique<ScannerSim>(horizontal_model_, truth_.laser_horizontal,
                                             "laser_horizontal", *world_, trajectory_, clock_,
                                             Rng(seed, kHorizontalStream), extras);
  extras.clock = truth_.profile_clock;
  extras.effects_seed = stream_seed(seed, kProfileEffects);
  profile_ =
      std::make_unique<ScannerSim>(rig.profile_scanner, truth_.laser_profile, "laser_profile",
                                   *world_, trajectory_, clock_, Rng(seed, kProfileStream), extras);
  imu_ = std::make_unique<ImuSim>(rig.imu_model, truth_.imu, trajectory_, clock_,
                                  Rng(seed, kImuStream), effects.floor.enabled, truth_.imu_clock);
  if (effects.wheel_encoders.enabled)
    odometry_ =
        std::make_unique<OdometrySim>(effects.wheel_encoders, platform.half_track_m, trajectory_,
                                      clock_, Rng(seed, kOdometryStream), truth_.odometry_clock);
  const double total = trajectory_.duration_s();
  const double begin = std::min(options.begin_s, total);
  const double end = options.duration_s > 0.0 ? std::min(total, begin + options.duration_s) : total;
  begin_utime_ = start_utime + std::llround(begin * 1e6);
  end_utime_ = start_utime + std::llround(end * 1e6);
  profile_every_ = options.profile_every;
  // First sample of every stream at or after the beginning.
  for (int s = 0; s < kStreams; ++s) {
    if (s == 4 && !odometry_) continue;
    while (stream_utime(s) < begin_utime_) next_index_[s] += s == 3 ? profile_every_ : 1;
  }
}

int64_t Simulator::stream_utime(int s) const {
  const int64_t k = next_index_[s];
  switch (s) {
    case 0:
      return clock_.sample_utime(k, rig_.ground_truth_rate_hz);
    case 1:
      return imu_->sample_utime(k);
    case 2:
      return horizontal_->sweep_utime(k);
    case 3:
      return profile_->sweep_utime(k);
    default:
      return odometry_->sample_utime(k);
  }
}

int64_t Simulator::stream_stamp(int s) const {
  const int64_t k = next_index_[s];
  int64_t u = 0;
  switch (s) {
    case 0: {
      // The truth in the horizontal scanner's time base (its clock without jitter): every pose the
      // graph estimates carries a scan's stamp, and no sensor of the cart sees true time, so an
      // estimate is compared with the truth at the instant its stamp names on the scanner's
      // clock. Stamped in true time, a key pose on an arc read omega x (offset + drift x t) off
      // in heading (41 ppm after 700 s at 0.6 rad/s: 1.2 deg) that no process could observe.
      const int64_t u_true = clock_.sample_utime(k, rig_.ground_truth_rate_hz);
      return truth_.horizontal_clock.reading(u_true, clock_.seconds(u_true));
    }
    case 1:
      u = imu_->sample_stamp(k);
      break;
    case 2:
      u = horizontal_->sweep_stamp(k);
      break;
    case 3:
      u = profile_->sweep_stamp(k);
      break;
    default:
      u = odometry_->sample_stamp(k);
      break;
  }
  // A stream's stamps never go backwards (a driver stamps in arrival order).
  return std::max(u, last_stamp_[s] + 1);
}

std::optional<SimEvent> Simulator::next() {
  // The stream whose next message is stamped earliest (a stream ends at the run's end in true
  // time); ties go to the lower stream number.
  int best = -1;
  int64_t best_stamp = 0;
  for (int s = 0; s < kStreams; ++s) {
    if (s == 4 && !odometry_) continue;
    if (stream_utime(s) > end_utime_) continue;
    const int64_t u = stream_stamp(s);
    if (best < 0 || u < best_stamp) {
      best = s;
      best_stamp = u;
    }
  }
  if (best < 0) return std::nullopt;
  const int64_t k = next_index_[best];
  const int64_t true_utime = stream_utime(best);
  next_index_[best] += best == 3 ? profile_every_ : 1;
  last_stamp_[best] = best_stamp;
  SimEvent ev;
  ev.utime = best_stamp;
  switch (best) {
    case 0: {
      ev.kind = SimEvent::Kind::kGroundTruth;
      const Pose2 p = trajectory_.pose(clock_.seconds(true_utime));
      ev.ground_truth = {best_stamp, p, trajectory_.lift(p)};
      break;
    }
    case 1:
      ev.kind = SimEvent::Kind::kImu;
      ev.imu = imu_->sample(k);
      ev.imu.utime = best_stamp;
      break;
    case 2:
      ev.kind = SimEvent::Kind::kScanHorizontal;
      ev.scan = horizontal_->sweep(k);
      break;
    case 3:
      ev.kind = SimEvent::Kind::kScanProfile;
      ev.scan = profile_->sweep(k);
      break;
    default:
      ev.kind = SimEvent::Kind::kOdometry;
      ev.odometry = odometry_->sample(k);
      ev.odometry.utime = best_stamp;
      break;
  }
  if (ev.kind == SimEvent::Kind::kScanHorizontal || ev.kind == SimEvent::Kind::kScanProfile) {
    // Keep utime_first equal to the message time even where the stamp was held back.
    ev.scan.utime_last += best_stamp - ev.scan.utime_first;
    ev.scan.utime_first = best_stamp;
  }
  return ev;
}

}  // namespace traverse::sim
