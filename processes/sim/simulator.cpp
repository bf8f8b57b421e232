#include "simulator.hpp"

#include <cmath>
#include <stdexcept>

namespace traverse::sim {
namespace {

// Independent random streams derived from the seed.
enum Stream : uint64_t {
  kTrajectoryStream = 0,
  kHorizontalStream = 1,
  kProfileStream = 2,
  kImuStream = 3
};

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

Simulator::Simulator(const WorldSpec& world, const RouteSpec& route, const RigConfig& rig,
                     const PlatformConfig& platform, uint64_t seed, int64_t start_utime,
                     const RunOptions& options)
    : rig_(rig),
      world_(world),
      trajectory_rng_(seed, kTrajectoryStream),
      trajectory_(checked(route, world), platform, trajectory_rng_),
      clock_{start_utime},
      horizontal_model_(find_horizontal_model(rig, route.horizontal_scanner)),
      horizontal_(horizontal_model_, rig.laser_horizontal, "laser_horizontal", world_, trajectory_,
                  clock_, Rng(seed, kHorizontalStream)),
      profile_(rig.profile_scanner, rig.laser_profile, "laser_profile", world_, trajectory_, clock_,
               Rng(seed, kProfileStream)),
      imu_(rig.imu_model, rig.imu, trajectory_, clock_, Rng(seed, kImuStream)) {
  if (rig.ground_truth_rate_hz <= 0 || rig.imu_model.rate_hz <= 0)
    throw std::runtime_error("rig rates must be > 0");
  if (options.begin_s < 0.0 || options.profile_every < 1)
    throw std::runtime_error("begin must be >= 0 s and profile decimation >= 1");
  const double total = trajectory_.duration_s();
  const double begin = std::min(options.begin_s, total);
  const double end = options.duration_s > 0.0 ? std::min(total, begin + options.duration_s) : total;
  begin_utime_ = start_utime + std::llround(begin * 1e6);
  end_utime_ = start_utime + std::llround(end * 1e6);
  profile_every_ = options.profile_every;
  // First sample of every stream at or after the beginning.
  for (int s = 0; s < kStreams; ++s) {
    while (stream_utime(s) < begin_utime_) next_index_[s] += s == 3 ? profile_every_ : 1;
  }
}

int64_t Simulator::stream_utime(int s) const {
  const int64_t k = next_index_[s];
  switch (s) {
    case 0:
      return clock_.sample_utime(k, rig_.ground_truth_rate_hz);
    case 1:
      return imu_.sample_utime(k);
    case 2:
      return horizontal_.sweep_utime(k);
    default:
      return profile_.sweep_utime(k);
  }
}

std::optional<SimEvent> Simulator::next() {
  // The stream whose next message is earliest; ties go to the lower stream number.
  int best = -1;
  int64_t best_utime = 0;
  for (int s = 0; s < kStreams; ++s) {
    const int64_t u = stream_utime(s);
    if (u > end_utime_) continue;
    if (best < 0 || u < best_utime) {
      best = s;
      best_utime = u;
    }
  }
  if (best < 0) return std::nullopt;
  const int64_t k = next_index_[best];
  next_index_[best] += best == 3 ? profile_every_ : 1;
  SimEvent ev;
  ev.utime = best_utime;
  switch (best) {
    case 0:
      ev.kind = SimEvent::Kind::kGroundTruth;
      ev.ground_truth = {best_utime, trajectory_.pose(clock_.seconds(best_utime))};
      break;
    case 1:
      ev.kind = SimEvent::Kind::kImu;
      ev.imu = imu_.sample(k);
      break;
    case 2:
      ev.kind = SimEvent::Kind::kScanHorizontal;
      ev.scan = horizontal_.sweep(k);
      break;
    default:
      ev.kind = SimEvent::Kind::kScanProfile;
      ev.scan = profile_.sweep(k);
      break;
  }
  return ev;
}

}  // namespace traverse::sim
