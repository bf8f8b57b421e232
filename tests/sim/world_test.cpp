#include "world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "config.hpp"
#include "rig.hpp"
#include "rng.hpp"
#include "simulator.hpp"

namespace traverse::sim {
namespace {

WorldSpec one_room() {
  WorldSpec w;
  w.name = "room";
  w.ceiling_z = 3.0;
  w.materials = {{"wall", 0.7, 1.0, 0.0}, {"floor", 0.3, 1.0, 0.0}, {"ceiling", 0.8, 1.0, 0.0}};
  w.walls = {{{{10, -5}, {10, 5}}, {0.0, 2.0}, false, "wall", ""}};
  w.pillars = {{"P1", 5.0, 2.0, 0.5, {0.0, 2.0}, "wall", ""}};
  w.boxes = {{3.0, -2.0, 0.0, {1.0, 1.0, 1.0}, 0.0, "wall", ""}};
  return w;
}

TEST(World, RayMeetsWallPillarBoxFloorAndCeiling) {
  const World world(one_room());
  const Eigen::Vector3d o(0, 0, 0.5);
  auto hit = world.raycast(o, Eigen::Vector3d::UnitX(), 40.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 10.0, 1e-12);
  EXPECT_NEAR(hit->normal.x(), -1.0, 1e-12);
  // Above the wall's top the ray flies on and meets nothing within range.
  EXPECT_FALSE(world.raycast(Eigen::Vector3d(0, 0, 2.5), Eigen::Vector3d::UnitX(), 40.0));
  // Pillar of radius 0.5 at (5, 2): a ray along y = 2 meets it at x = 4.5.
  hit = world.raycast(Eigen::Vector3d(0, 2, 0.5), Eigen::Vector3d::UnitX(), 40.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4.5, 1e-9);
  // Box [2.5, 3.5] x [-2.5, -1.5], 1 m high: its side at x = 2.5, its top seen from above.
  hit = world.raycast(Eigen::Vector3d(0, -2, 0.5), Eigen::Vector3d::UnitX(), 40.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2.5, 1e-12);
  hit = world.raycast(Eigen::Vector3d(3, -2, 2.5), -Eigen::Vector3d::UnitZ(), 40.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 1.5, 1e-12);
  EXPECT_NEAR(hit->normal.z(), 1.0, 1e-12);
  hit = world.raycast(Eigen::Vector3d(-3, 0, 1.0), Eigen::Vector3d(0.6, 0, -0.8), 40.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 1.25, 1e-12);  // floor
  hit = world.raycast(Eigen::Vector3d(-3, 0, 1.0), Eigen::Vector3d::UnitZ(), 40.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 2.0, 1e-12);  // ceiling
}

TEST(World, GridWalkAgreesWithOneBigCell) {
  WorldSpec spec;
  load_config("configs/worlds/office.yaml", spec);
  const World fine(spec, 0.5), coarse(spec, 500.0);
  Rng rng(7);
  int hits = 0;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d o(rng.uniform(0, 58), rng.uniform(-2, 18), rng.uniform(0.1, 2.7));
    const double az = rng.uniform(-std::numbers::pi, std::numbers::pi);
    const double el = rng.uniform(-0.6, 0.6);
    const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const auto a = fine.raycast(o, d, 41.0), b = coarse.raycast(o, d, 41.0);
    ASSERT_EQ(a.has_value(), b.has_value()) << i;
    if (!a) continue;
    ++hits;
    EXPECT_NEAR(a->t, b->t, 1e-9) << i;
  }
  EXPECT_GT(hits, 2900);  // indoors almost every ray meets something
}

TEST(World, DistanceToSurface) {
  const World world(one_room());
  EXPECT_NEAR(world.distance_to_surface({9.7, 0.0, 1.0}), 0.3, 1e-12);
  EXPECT_NEAR(world.distance_to_surface({-3.0, 0.0, 0.1}), 0.1, 1e-12);       // floor
  EXPECT_NEAR(world.distance_to_surface({5.0, 2.8, 1.0}), 0.3, 1e-12);        // pillar side
  EXPECT_NEAR(world.distance_to_surface({3.0, -2.0, 1.2}), 0.2, 1e-12);       // box top
  EXPECT_NEAR(world.distance_to_surface({-3.0, 0.0, 1.5}, 0.5), 0.5, 1e-12);  // capped search
  EXPECT_NEAR(world.clearance_2d({8.0, 0.0}, 0.0, 1.0), 2.0, 1e-12);
}

TEST(World, RejectsUnknownMaterial) {
  WorldSpec w = one_room();
  w.walls[0].material = "marble";
  EXPECT_THROW(World{w}, std::runtime_error);
}

TEST(World, ShippedWorldsLoadAndOfficeHasEightPillars) {
  for (const char* name : {"office", "court", "corridor"}) {
    WorldSpec spec;
    ASSERT_NO_THROW(load_config(std::string("configs/worlds/") + name + ".yaml", spec)) << name;
    EXPECT_EQ(spec.name, name);
    EXPECT_NO_THROW(World{spec});
  }
  WorldSpec office;
  load_config("configs/worlds/office.yaml", office);
  int pillars = 0;
  for (const auto& p : office.pillars) pillars += p.id.size() == 2 && p.id[0] == 'P';
  EXPECT_EQ(pillars, 8);
  WorldSpec court;
  load_config("configs/worlds/court.yaml", court);
  EXPECT_LT(court.ceiling_z, court.floor_z);  // outdoors
}

// configs/rig.yaml restates the built-in rig, and configs/sim.yaml the built-in platform.
TEST(Configs, RigAndSimFilesMatchTheDefaults) {
  RigConfig file, defaults;
  load_config("configs/rig.yaml", file);
  EXPECT_DOUBLE_EQ(file.laser_profile.pitch, defaults.laser_profile.pitch);
  EXPECT_DOUBLE_EQ(file.laser_horizontal.z, defaults.laser_horizontal.z);
  EXPECT_DOUBLE_EQ(file.imu.x, defaults.imu.x);
  ASSERT_EQ(file.horizontal_scanners.size(), defaults.horizontal_scanners.size());
  for (std::size_t i = 0; i < file.horizontal_scanners.size(); ++i) {
    const auto &a = file.horizontal_scanners[i], &b = defaults.horizontal_scanners[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.points, b.points);
    EXPECT_DOUBLE_EQ(a.rate_hz, b.rate_hz);
    EXPECT_DOUBLE_EQ(a.angle_step_rad, b.angle_step_rad);
    EXPECT_DOUBLE_EQ(a.range.noise_25m_dark_m, b.range.noise_25m_dark_m);
    EXPECT_DOUBLE_EQ(a.range.range_at_90_percent_m, b.range.range_at_90_percent_m);
  }
  EXPECT_EQ(file.profile_scanner.points, defaults.profile_scanner.points);
  EXPECT_NEAR(file.profile_scanner.angle_step_rad, defaults.profile_scanner.angle_step_rad, 1e-15);
  EXPECT_DOUBLE_EQ(file.imu_model.gyro_arw_rad_sqrt_s, defaults.imu_model.gyro_arw_rad_sqrt_s);
  SimConfig sim, sim_defaults;
  load_config("configs/sim.yaml", sim);
  EXPECT_EQ(sim.start_utime, sim_defaults.start_utime);
  ASSERT_EQ(sim.platform.vibration.size(), sim_defaults.platform.vibration.size());
  for (std::size_t i = 0; i < sim.platform.vibration.size(); ++i)
    EXPECT_DOUBLE_EQ(sim.platform.vibration[i].amplitude,
                     sim_defaults.platform.vibration[i].amplitude);
}

}  // namespace
}  // namespace traverse::sim
