// Mapper: each point is placed with the pose at its own time and the scanner extrinsic; range and
// footprint filters; profiles wait for poses; moved segments (large or small, repeated, with
// profiles arriving between the moves) give the same cloud and OctoMap as a map built from
// scratch with the final trajectory; PLY round trip.
#include "mapper.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>

#include "ply.hpp"

namespace traverse::mapper {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;
constexpr int kBeams = 720;

Eigen::Isometry3d tilted_extrinsic() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(80.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitY())
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.45, 0.0, 1.0);
  return T;
}

// True motion: 0.5 m/s forward while turning at 0.3 rad/s.
Pose2 truth(int64_t utime, double y_offset = 0.0) {
  const double t = 1e-6 * static_cast<double>(utime - kT0);
  return Pose2(0.5 * t, y_offset + 0.05 * t * t, 0.3 * t);
}

// Segment k covers [k, k + 1] x 100 ms with poses every 10 ms.
TrajectorySegment segment(int k, double y_offset = 0.0) {
  TrajectorySegment s;
  s.key_id_first = k;
  for (int i = 0; i <= 10; ++i) {
    const int64_t t = kT0 + (k * 10 + i) * 10'000;
    s.utimes.push_back(t);
    s.T_world_base.push_back(truth(t, y_offset));
  }
  return s;
}

// A full circle of 2.5 m returns, with a few out-of-range beams, over 33 ms starting at t0.
Profile profile(int64_t t0) {
  Profile p;
  p.utime_first = t0;
  p.utime_last = t0 + 33'000;
  p.angle_first = static_cast<float>(-std::numbers::pi);
  p.angle_step = static_cast<float>(2 * std::numbers::pi / kBeams);
  for (int i = 0; i < kBeams; ++i) {
    p.ranges.push_back(i % 100 == 0 ? 7.0f : (i % 100 == 1 ? 0.3f : 2.5f));
    p.intensities.push_back(static_cast<uint8_t>(i % 256));
  }
  return p;
}

MapperConfig small_footprint() {
  MapperConfig c;
  c.footprint = {-0.1, 0.1, -0.1, 0.1, 0.02, 0.5};  // nothing of the circle falls in it
  return c;
}

TEST(Mapper, PlacesEveryPointWithThePoseAtItsOwnTime) {
  Mapper m(small_footprint(), tilted_extrinsic());
  ASSERT_TRUE(m.add_profile(profile(kT0 + 20'000)));
  EXPECT_EQ(m.pending(), 1u);  // no poses yet
  ASSERT_TRUE(m.set_segment(segment(0)));
  EXPECT_EQ(m.pending(), 0u);
  EXPECT_EQ(m.profiles(), 1u);
  EXPECT_EQ(m.points(), kBeams - 16);  // 8 returns at 7 m and 8 at 0.3 m dropped
  int n = 0;
  const Eigen::Isometry3d T_bl = tilted_extrinsic();
  m.for_each_point([&](const CloudPoint& p) {
    const Pose2 T_wb = truth(p.utime);
    Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();
    T_world_base.linear() =
        Eigen::AngleAxisd(T_wb.theta(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_world_base.translation() = Eigen::Vector3d(T_wb.x(), T_wb.y(), 0);
    const int beam =
        static_cast<int>(std::lround((p.utime - (kT0 + 20'000)) * (kBeams - 1) / 33'000.0));
    const double a = -std::numbers::pi + beam * 2 * std::numbers::pi / kBeams;
    const Eigen::Vector3d expected =
        T_world_base * T_bl * Eigen::Vector3d(2.5 * std::cos(a), 2.5 * std::sin(a), 0);
    // Linear interpolation between poses 10 ms apart on a curve, float output: within 0.2 mm.
    EXPECT_LT((p.p_world.cast<double>() - expected).norm(), 2e-4);
    EXPECT_EQ(p.key_id, 0);
    ++n;
  });
  EXPECT_EQ(n, m.points());
}

TEST(Mapper, FiltersThePlatformFootprint) {
  MapperConfig c;
  c.footprint = {-1.0, 1.0, -3.0, 3.0, 0.02, 1.3};  // the cart reaches 1 m ahead and 1.3 m up
  Mapper m(c, tilted_extrinsic());
  m.set_segment(segment(0));
  m.add_profile(profile(kT0));
  EXPECT_GT(m.points_filtered(), 100);
  m.for_each_point([&](const CloudPoint& p) {
    const Pose2 T_base_world = truth(p.utime).inverse();
    const Eigen::Vector2d q = T_base_world * Eigen::Vector2d(p.p_world.x(), p.p_world.y());
    const bool inside = q.x() > -1.0 && q.x() < 1.0 && std::abs(q.y()) < 3.0 &&
                        p.p_world.z() > 0.02 && p.p_world.z() < 1.3;
    EXPECT_FALSE(inside);
  });
}

// Occupied leaves and their log-odds (voxels a move vacated stay as free leaves).
std::map<std::tuple<int, int, int>, float> leaves(const octomap::OcTree& t) {
  std::map<std::tuple<int, int, int>, float> out;
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
    const auto k = it.getKey();
    if (t.isNodeOccupied(*it)) out[{k[0], k[1], k[2]}] = it->getLogOdds();
  }
  return out;
}

TEST(Mapper, MovedSegmentsGiveTheSameMapAsAFreshBuild) {
  MapperConfig c = small_footprint();
  c.resolution_m = 0.05;
  Mapper moved(c, tilted_extrinsic()), fresh(c, tilted_extrinsic());
  for (int k = 0; k < 4; ++k) moved.set_segment(segment(k));
  for (int64_t t = kT0; t + 33'000 <= kT0 + 400'000; t += 33'333) moved.add_profile(profile(t));
  EXPECT_EQ(moved.profiles(), 12u);
  // A loop closure moves segments 2 and 3 by 7 cm.
  moved.set_segment(segment(2, 0.07));
  moved.set_segment(segment(3, 0.07));
  EXPECT_GE(moved.apply_moves(), 6u);
  for (int k = 0; k < 4; ++k) fresh.set_segment(segment(k, k >= 2 ? 0.07 : 0.0));
  for (int64_t t = kT0; t + 33'000 <= kT0 + 400'000; t += 33'333) fresh.add_profile(profile(t));
  const auto a = leaves(moved.octree()), b = leaves(fresh.octree());
  EXPECT_GT(b.size(), 500u);
  EXPECT_EQ(a, b);
  EXPECT_EQ(moved.occupied_voxels(), fresh.occupied_voxels());
  EXPECT_EQ(moved.occupied_voxels(), b.size());
  std::vector<CloudPoint> pa, pb;
  moved.for_each_point([&](const CloudPoint& p) { pa.push_back(p); });
  fresh.for_each_point([&](const CloudPoint& p) { pb.push_back(p); });
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa[i].p_world, pb[i].p_world);
    EXPECT_EQ(pa[i].key_id, pb[i].key_id);
  }
}

TEST(Mapper, VoxelsAreOctoMapsKeysOfThePoints) {
  // The mapper computes voxel keys itself (inline); they must be OctoMap's own.
  MapperConfig c = small_footprint();
  c.resolution_m = 0.03;
  Mapper m(c, tilted_extrinsic());
  m.set_segment(segment(0));
  m.add_profile(profile(kT0 + 20'000));
  std::map<std::tuple<int, int, int>, float> expected;
  const float one_hit = m.octree().getProbHitLog();
  m.for_each_point([&](const CloudPoint& p) {
    octomap::OcTreeKey k;
    ASSERT_TRUE(m.octree().coordToKeyChecked(p.p_world.x(), p.p_world.y(), p.p_world.z(), k));
    expected[{k[0], k[1], k[2]}] = one_hit;
  });
  EXPECT_GT(expected.size(), 100u);
  EXPECT_EQ(leaves(m.octree()), expected);
}

// Segment k moved by dy [m] and turned by dth [rad].
TrajectorySegment shifted(int k, double dy, double dth) {
  TrajectorySegment s = segment(k);
  for (Pose2& T : s.T_world_base) T = Pose2(T.x(), T.y() + dy, T.theta() + dth);
  return s;
}

// Segment k with other times: poses every 20 ms, 4 mm aside.
TrajectorySegment coarse(int k) {
  TrajectorySegment s;
  s.key_id_first = k;
  for (int i = 0; i <= 5; ++i) {
    const int64_t t = kT0 + (k * 10 + 2 * i) * 10'000;
    s.utimes.push_back(t);
    s.T_world_base.push_back(truth(t, 0.004));
  }
  return s;
}

TEST(Mapper, RepeatedSmallMovesGiveTheSameMapAsAFreshBuild) {
  // Millimetre moves at 2 cm leave most voxels of a profile where they were: only those left or
  // entered change. Segments move twice before the moves are applied, a profile arrives between
  // two moves of its segment, new segments arrive meanwhile, and one segment comes with other
  // times; the map must equal one built from scratch with the final trajectory.
  MapperConfig c = small_footprint();
  Mapper moved(c, tilted_extrinsic()), fresh(c, tilted_extrinsic());
  std::vector<int64_t> times;
  for (int64_t t = kT0; t + 33'000 <= kT0 + 600'000; t += 33'333) times.push_back(t);
  const int64_t late = kT0 + 215'000;  // inside segment 2
  for (int k = 0; k < 4; ++k) moved.set_segment(segment(k));
  for (int64_t t : times) moved.add_profile(profile(t));
  EXPECT_EQ(moved.pending(), 6u);  // those after 400 ms wait for segments 4 and 5
  moved.set_segment(shifted(1, 0.0015, 0.0));
  moved.set_segment(shifted(2, 0.001, 2e-4));
  moved.add_profile(profile(late));
  moved.set_segment(shifted(1, 0.003, -1e-4));
  moved.set_segment(shifted(2, 0.002, 3e-4));
  moved.set_segment(segment(4));
  moved.set_segment(segment(5));
  EXPECT_EQ(moved.pending(), 0u);
  EXPECT_GE(moved.apply_moves(), 6u);  // profiles placed before the moves in segments 1 and 2
  moved.set_segment(coarse(3));
  moved.set_segment(segment(1));
  moved.apply_moves();

  fresh.set_segment(segment(0));
  fresh.set_segment(segment(1));
  fresh.set_segment(shifted(2, 0.002, 3e-4));
  fresh.set_segment(coarse(3));
  fresh.set_segment(segment(4));
  fresh.set_segment(segment(5));
  for (int64_t t : times) fresh.add_profile(profile(t));
  fresh.add_profile(profile(late));
  EXPECT_EQ(moved.profiles(), fresh.profiles());
  const auto a = leaves(moved.octree()), b = leaves(fresh.octree());
  EXPECT_GT(b.size(), 2000u);
  EXPECT_EQ(a, b);
  EXPECT_EQ(moved.occupied_voxels(), b.size());
  std::vector<CloudPoint> pa, pb;
  moved.for_each_point([&](const CloudPoint& p) { pa.push_back(p); });
  fresh.for_each_point([&](const CloudPoint& p) { pb.push_back(p); });
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    EXPECT_EQ(pa[i].p_world, pb[i].p_world);
    EXPECT_EQ(pa[i].key_id, pb[i].key_id);
  }
}

TEST(Mapper, PlyRoundTrip) {
  Mapper m(small_footprint(), tilted_extrinsic());
  m.set_segment(segment(0));
  m.add_profile(profile(kT0 + 10'000));
  const std::string path =
      (std::filesystem::temp_directory_path() / "traverse_mapper_test.ply").string();
  ASSERT_TRUE(write_ply(path, m));
  std::string error;
  auto back = read_ply(path, &error);
  ASSERT_TRUE(back) << error;
  ASSERT_EQ(static_cast<int64_t>(back->size()), m.points());
  std::size_t i = 0;
  m.for_each_point([&](const CloudPoint& p) {
    EXPECT_EQ((*back)[i].p_world, p.p_world);
    EXPECT_EQ((*back)[i].intensity, p.intensity);
    EXPECT_NEAR(static_cast<double>((*back)[i].utime - p.utime), 0.0, 1.0);
    ++i;
  });
  std::filesystem::remove(path);
  EXPECT_FALSE(read_ply(path, &error));
}

}  // namespace
}  // namespace traverse::mapper
