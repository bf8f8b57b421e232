// The mapper's screen preview: one point per cell of its grid, in the base frame at the profile's
// time, from the mapper's own placement, sent once per profile (a loop closure moves no preview
// point: the viewer moves the profile's pose), in messages of a bounded number of points.
#include "preview.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "mapper.hpp"

namespace traverse::mapper {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;

TEST(CloudPreview, KeepsOnePointPerCellInTheBaseFrame) {
  CloudPreview preview({.channel = "CLOUD_PREVIEW", .cell_m = 0.1, .max_points_per_message = 3});
  const Pose2 T(10.0, 5.0, std::numbers::pi / 2);  // base at (10, 5), facing +y
  // Two points in one cell, one in another; p_world = T * (1, 0) = (10, 6).
  preview.add(kT0, T, {{10.0f, 6.0f, 1.5f}, {10.01f, 6.02f, 1.51f}, {10.5f, 6.0f, 0.2f}});
  EXPECT_EQ(preview.points(), 2);
  // A later profile over the same cells adds nothing; one new cell adds one point.
  preview.add(kT0 + 1, T, {{10.02f, 6.01f, 1.52f}, {12.0f, 6.0f, 0.0f}});
  EXPECT_EQ(preview.points(), 3);
  EXPECT_EQ(preview.cells(), 3);
  const auto groups = preview.take();
  ASSERT_EQ(groups.size(), 1u);
  ASSERT_EQ(groups[0].size(), 2u);
  const PreviewProfile& first = groups[0][0];
  EXPECT_EQ(first.utime, kT0);
  ASSERT_EQ(first.p_base_mm.size(), 2u);
  EXPECT_EQ(first.p_base_mm[0], (std::array<int16_t, 3>{1000, 0, 1500}));    // 1 m ahead
  EXPECT_EQ(first.p_base_mm[1], (std::array<int16_t, 3>{1000, -500, 200}));  // and 0.5 m right
  EXPECT_TRUE(preview.take().empty());                                       // each once
}

TEST(CloudPreview, SplitsLongProfilesAcrossMessages) {
  CloudPreview preview({.channel = "CLOUD_PREVIEW", .cell_m = 0.1, .max_points_per_message = 4});
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 10; ++i) pts.emplace_back(0.2f * i, 0.0f, 0.0f);
  preview.add(kT0, Pose2(), pts);
  const auto groups = preview.take();
  ASSERT_EQ(groups.size(), 3u);  // 4 + 4 + 2 points, every part of the same profile
  std::size_t n = 0;
  for (const auto& g : groups) {
    for (const auto& p : g) {
      EXPECT_EQ(p.utime, kT0);
      n += p.p_base_mm.size();
    }
  }
  EXPECT_EQ(n, 10u);
}

TEST(CloudPreview, ComesFromTheMappersPlacementOncePerProfile) {
  MapperConfig config;
  config.footprint = {-0.1, 0.1, -0.1, 0.1, 0.02, 0.5};
  Eigen::Isometry3d T_base_laser = Eigen::Isometry3d::Identity();
  T_base_laser.translation() = Eigen::Vector3d(0.4, 0.0, 1.0);
  Mapper mapper(config, T_base_laser);
  int calls = 0;
  Pose2 pose_seen;
  std::vector<Eigen::Vector3f> points_seen;
  mapper.on_first_placement([&](int64_t, const Pose2& T, const std::vector<Eigen::Vector3f>& p) {
    ++calls;
    pose_seen = T;
    points_seen = p;
  });
  Profile p;
  p.utime_first = kT0 + 10'000;
  p.utime_last = kT0 + 20'000;
  p.angle_first = 0.0f;
  p.angle_step = 0.01f;
  p.ranges.assign(11, 2.0f);
  ASSERT_TRUE(mapper.add_profile(p));
  EXPECT_EQ(calls, 0);  // no trajectory yet
  auto segment = [](double y) {
    TrajectorySegment s;
    s.key_id_first = 0;
    for (int i = 0; i <= 10; ++i) {
      s.utimes.push_back(kT0 + i * 5'000);
      s.T_world_base.emplace_back(0.0, y, 0.0);
    }
    return s;
  };
  ASSERT_TRUE(mapper.set_segment(segment(0.0)));
  ASSERT_EQ(calls, 1);
  EXPECT_NEAR(pose_seen.y(), 0.0, 1e-12);
  ASSERT_EQ(points_seen.size(), 11u);
  EXPECT_NEAR(points_seen[0].x(), 2.4f, 1e-5);  // 2 m along the beam from the scanner at 0.4 m
  EXPECT_NEAR(points_seen[0].z(), 1.0f, 1e-5);
  // A loop closure moves the segment: the points move in the map, the preview is not called.
  ASSERT_TRUE(mapper.set_segment(segment(0.3)));
  mapper.apply_moves();
  EXPECT_EQ(calls, 1);
}

}  // namespace
}  // namespace traverse::mapper
