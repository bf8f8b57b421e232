// The simulated route the mapper's benchmarks (bench.cpp, preview_bench.cpp) feed on: world,
// route and rig read from their files, the simulator made on them (seed 1, ideal profile), and
// its tilted scanner's scans as the Mapper's profiles.
#pragma once

#include <memory>
#include <string>

#include "config.hpp"
#include "mapper.hpp"
#include "simulator.hpp"

namespace traverse::mapper {

struct BenchSim {
  sim::WorldSpec world;
  sim::RouteSpec route;
  sim::RigConfig rig;
  std::unique_ptr<sim::Simulator> simulator;  // holds references to the specs above

  BenchSim(const std::string& world_file, const std::string& route_file,
           const std::string& rig_file, const sim::RunOptions& options) {
    load_config(world_file, world);
    load_config(route_file, route);
    load_config(rig_file, rig);
    simulator = std::make_unique<sim::Simulator>(world, route, rig, sim::PlatformConfig{}, 1,
                                                 1'700'000'000'000'000, options);
  }
  BenchSim(const BenchSim&) = delete;
  BenchSim& operator=(const BenchSim&) = delete;
};

inline Profile profile_of(const sim::ScanData& s) {
  Profile p;
  p.utime_first = s.utime_first;
  p.utime_last = s.utime_last;
  p.angle_first = s.angle_first;
  p.angle_step = s.angle_step;
  p.range_min = s.range_min;
  p.range_max = s.range_max;
  p.ranges = s.ranges;
  p.intensities = s.intensities;
  return p;
}

}  // namespace traverse::mapper
