// Cloud evaluation on a tiny true world: a shifted cloud gives the shift back as point-to-surface
// distance, pillar centre error and corridor length error; end walls are probed only inside their
// intervals.
#include "cloud_eval.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace traverse::mapper {
namespace {

sim::WorldSpec tiny_world() {
  sim::WorldSpec w;
  w.name = "tiny";
  w.floor_z = 0.0;
  w.ceiling_z = 3.0;
  w.materials = {{"wall", 0.7, 1.0, 0.0},
                 {"concrete", 0.4, 1.0, 0.0},
                 {"floor", 0.3, 1.0, 0.0},
                 {"ceiling", 0.8, 1.0, 0.0}};
  sim::WallSpec a, b;
  a.points = {{0, -2}, {0, 2}};
  b.points = {{10, -2}, {10, 2}};
  w.walls = {a, b};
  sim::PillarSpec p;
  p.id = "P1";
  p.x = 5.0;
  p.y = 0.0;
  p.radius = 0.3;
  w.pillars = {p};
  return w;
}

// Points on the true surfaces (both end walls, the pillar), all moved by `shift`.
std::vector<CloudPoint> cloud(const Eigen::Vector3f& shift) {
  std::vector<CloudPoint> out;
  for (int i = 0; i < 400; ++i) {
    const float y = -1.9f + 3.8f * static_cast<float>(i) / 400.0f;
    const float z = 0.4f + 2.0f * static_cast<float>(i % 20) / 20.0f;
    out.push_back({Eigen::Vector3f(0.0f, y, z) + shift, 0, 0, 0});
    out.push_back({Eigen::Vector3f(10.0f, y, z) + shift, 0, 0, 0});
    // Only the half of the pillar seen from the west.
    const double a = std::numbers::pi / 2 + std::numbers::pi * i / 400.0;
    out.push_back({Eigen::Vector3f(static_cast<float>(5.0 + 0.3 * std::cos(a)),
                                   static_cast<float>(0.3 * std::sin(a)), z) +
                       shift,
                   0, 0, 0});
  }
  return out;
}

TEST(CloudEval, ShiftedCloudGivesTheShiftBack) {
  const sim::WorldSpec spec = tiny_world();
  const sim::World world(spec);
  CloudEvalConfig config;
  config.corridors = {{"main", {"x", 0.0, {{-1.5, 1.5}}}, {"x", 10.0, {{-1.5, -0.5}, {0.5, 1.5}}}}};
  const auto exact = evaluate_cloud(cloud(Eigen::Vector3f::Zero()), world, spec, config);
  EXPECT_LT(exact.surface.rmse, 1e-5);
  ASSERT_EQ(exact.pillar.n, 1);
  EXPECT_LT(exact.pillar.max, 1e-5);
  ASSERT_TRUE(exact.corridors[0].length_m);
  EXPECT_NEAR(*exact.corridors[0].length_m, 10.0, 1e-5);

  // 4 mm east: end walls and the pillar's west face are 4 mm off; the length is unchanged.
  const auto shifted = evaluate_cloud(cloud(Eigen::Vector3f(0.004f, 0, 0)), world, spec, config);
  EXPECT_NEAR(shifted.pillar.max, 0.004, 2e-5);
  EXPECT_NEAR(shifted.surface.p95, 0.004, 5e-4);
  EXPECT_NEAR(*shifted.corridors[0].length_m, 10.0, 1e-5);
}

// An end wall probed in two intervals: points between them (a shelf standing 5 cm in front of the
// wall) are left out, and the points counted are exactly those inside the intervals.
TEST(CloudEval, EndWallIsProbedOnlyInsideItsIntervals) {
  const sim::WorldSpec spec = tiny_world();
  const sim::World world(spec);
  std::vector<CloudPoint> pts = cloud(Eigen::Vector3f::Zero());
  int expected_b = 0;
  for (const CloudPoint& p : pts) {
    const float y = p.p_world.y();
    if (p.p_world.x() == 10.0f && ((y >= -1.5f && y <= -0.5f) || (y >= 0.5f && y <= 1.5f))) {
      ++expected_b;
    }
  }
  for (int i = 0; i < 2000; ++i) {  // the shelf face: many points, all 5 cm off the wall
    pts.push_back(
        {Eigen::Vector3f(9.95f, -0.4f + 0.8f * static_cast<float>(i) / 2000.0f, 1.0f), 0, 0, 0});
  }
  CloudEvalConfig config;
  config.corridors = {{"main", {"x", 0.0, {{-1.5, 1.5}}}, {"x", 10.0, {{-1.5, -0.5}, {0.5, 1.5}}}}};
  const auto r = evaluate_cloud(pts, world, spec, config, 1);
  ASSERT_TRUE(r.corridors[0].length_m);
  EXPECT_NEAR(*r.corridors[0].length_m, 10.0, 1e-5);
  EXPECT_EQ(r.corridors[0].points_b, expected_b);
  // One interval over the whole wall takes the shelf in: its median moves off the wall.
  config.corridors[0].end_b.across = {{-1.5, 1.5}};
  const auto biased = evaluate_cloud(pts, world, spec, config, 1);
  EXPECT_GT(std::abs(*biased.corridors[0].length_m - 10.0), 0.04);
}

TEST(CloudEval, BadCorridorIntervalsAreNamed) {
  CloudEvalConfig config;
  config.corridors = {{"lower", {"x", 0.0, {{0.2, 2.2}}}, {"x", 44.0, {{-1.8, -0.2}}}}};
  std::vector<CorridorSpec>& c = config.corridors;
  EXPECT_EQ(validate(config), std::nullopt);
  c[0].end_b.across = {{-0.2, -1.8}};
  ASSERT_TRUE(validate(config));
  EXPECT_NE(validate(config)->find("key 'corridors[0].end_b.across[0]'"), std::string::npos);
  c[0].end_b.across = {{-1.8, -0.2, 0.5}};
  EXPECT_TRUE(validate(config));
  c[0].end_b.across = {};
  EXPECT_TRUE(validate(config));
  c[0].end_b.across = {{-1.8, -0.2}};
  c[0].end_a.axis = "z";
  ASSERT_TRUE(validate(config));
  EXPECT_NE(validate(config)->find("corridors[0].end_a.axis"), std::string::npos);
}

TEST(CloudEval, DescribeGivesTheUsualStatistics) {
  const Stats s = describe({0.001, 0.002, 0.002, 0.003, 0.010}, 0.001);
  EXPECT_EQ(s.n, 5);
  EXPECT_NEAR(s.mean, 0.0036, 1e-12);
  EXPECT_NEAR(s.rmse, std::sqrt((1 + 4 + 4 + 9 + 100) * 1e-6 / 5), 1e-12);
  EXPECT_NEAR(s.mode, 0.0025, 1e-12);  // centre of the fullest 1 mm bin
  EXPECT_DOUBLE_EQ(s.min, 0.001);
  EXPECT_DOUBLE_EQ(s.max, 0.010);
}

}  // namespace
}  // namespace traverse::mapper
