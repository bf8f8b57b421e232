// The mapper's state (mapper_state.hpp): a node started on the state directory of another has the
// same map, voxel for voxel, after segments moved; a torn last record is cut off, a damaged one
// refused with the file named; the segment log is compacted to the newest versions.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <tuple>

#include "channels.hpp"
#include "mapper_node.hpp"
#include "test_profile.hpp"

namespace traverse::mapper {
namespace {

constexpr int64_t kT0 = 1'700'000'000'000'000;

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("traverse_mapper_state_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

Eigen::Isometry3d laser_on_mast() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.4, 0, 1.0);
  return T;
}

std::set<std::tuple<int, int, int>> voxels(const Mapper& m) {
  std::set<std::tuple<int, int, int>> out;
  const octomap::OcTree& tree = m.octree();
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (tree.isNodeOccupied(*it)) out.emplace(it.getKey()[0], it.getKey()[1], it.getKey()[2]);
  }
  return out;
}

// Profiles and trajectory segments (1 s each, straight north-east) published on a bus.
struct Feed {
  Bus bus{"memq://"};
  int64_t published_utime = 0;  // [us] of the last segments message
  void handle_all() {
    while (bus.lcm().handleTimeout(0) > 0) {
    }
  }
  void profile(int64_t t0) {
    std::vector<float> ranges;
    for (int i = 0; i < 360; ++i) ranges.push_back(1.5f + 0.01f * static_cast<float>(i % 50));
    ranges[7] = NAN;
    ranges[8] = 40.0f;  // beyond range_max_m: no point
    planar_scan_t s = test_profile(t0, std::move(ranges));
    bus.publish(channels::kScanProfile, s);
  }
  // Segment k over [k, k + 1] s, its poses shifted by `dy` [m].
  void segment(int k, int revision, double dy) {
    dense_segments_t m{};
    dense_segment_t s{};
    s.key_id_first = k;
    s.revision = revision;
    for (int i = 0; i <= 50; ++i) {
      const double t = k + i / 50.0;
      s.pose_utime.push_back(kT0 + static_cast<int64_t>(std::llround(t * 1e6)));
      s.x.push_back(0.5 * t);
      s.y.push_back(0.2 * t + dy);
      s.theta.push_back(0.1 * t);
    }
    s.n_poses = static_cast<int32_t>(s.pose_utime.size());
    // Publish times only go forward on a channel (the bus drops a message that goes back).
    published_utime = std::max(published_utime + 1, s.pose_utime.back());
    m.utime = published_utime;
    m.segments.push_back(s);
    m.n_segments = 1;
    bus.publish(channels::kDenseSegments, m);
  }
};

MapperConfig config_in(const std::filesystem::path& dir) {
  MapperConfig c;
  c.output_dir = (dir / "out").string();
  c.annotations_channel = "";
  c.preview.channel = "";
  return c;
}

TEST(MapperState, ANodeOnTheStateOfAnotherHasTheSameMapAfterMoves) {
  const auto dir = fresh_dir("same_map");
  const std::string state = (dir / "state").string();
  Feed a_feed;
  MapperNode a(a_feed.bus, config_in(dir), laser_on_mast(), {}, false, state);
  EXPECT_FALSE(a.resumed());
  for (int k = 0; k < 4; ++k) {
    for (int p = 0; p < 10; ++p) a_feed.profile(kT0 + k * 1'000'000 + p * 90'000);
    a_feed.segment(k, 0, 0.0);
    a_feed.handle_all();
  }
  // A loop closure moves segments 1 and 2 by 3 cm (revision 1), and a stale revision 0 of
  // segment 2 comes late: ignored, here and on resuming.
  a_feed.segment(1, 1, 0.03);
  a_feed.segment(2, 1, 0.03);
  a_feed.segment(2, 0, 0.0);
  a_feed.handle_all();
  a.finish();
  ASSERT_EQ(a.mapper().profiles(), 40u);
  ASSERT_GT(a.mapper().placed_points(), 1000) << a.mapper().pending();
  ASSERT_GT(a.mapper().profiles_replaced(), 0);

  Feed b_feed;
  MapperNode b(b_feed.bus, config_in(dir), laser_on_mast(), {}, false, state);
  ASSERT_TRUE(b.resumed());
  EXPECT_EQ(b.resumed()->profiles, 40u);
  EXPECT_EQ(b.resumed()->segments, 6u);  // the stale revision was never kept
  b.finish();
  EXPECT_EQ(b.mapper().placed_points(), a.mapper().placed_points());
  EXPECT_EQ(voxels(b.mapper()), voxels(a.mapper()));
  // Every point where the first node has it (the ranges kept as the mapper quantises them).
  std::vector<Eigen::Vector3f> pa, pb;
  a.mapper().for_each_point([&](const CloudPoint& p) { pa.push_back(p.p_world); });
  b.mapper().for_each_point([&](const CloudPoint& p) { pb.push_back(p.p_world); });
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) EXPECT_LT((pa[i] - pb[i]).norm(), 1e-6f) << i;
  std::filesystem::remove_all(dir);
}

TEST(MapperState, ATornLastRecordIsCutOffAndADamagedOneRefused) {
  const auto dir = fresh_dir("torn");
  const std::string state = (dir / "state").string();
  {
    Feed f;
    MapperNode n(f.bus, config_in(dir), laser_on_mast(), {}, false, state);
    for (int p = 0; p < 3; ++p) f.profile(kT0 + p * 90'000);
    f.segment(0, 0, 0.0);
    f.handle_all();
  }
  // A kill in the middle of a write leaves part of a record.
  std::ofstream(dir / "state" / "profiles.rec", std::ios::app) << "\x40\x00\x00\x00partial";
  {
    Feed f;
    MapperNode n(f.bus, config_in(dir), laser_on_mast(), {}, false, state);
    ASSERT_TRUE(n.resumed());
    EXPECT_EQ(n.resumed()->profiles, 3u);
    f.profile(kT0 + 300'000);  // appended after the intact records, the torn part gone
    f.handle_all();
  }
  {
    Feed f;
    MapperNode n(f.bus, config_in(dir), laser_on_mast(), {}, false, state);
    EXPECT_EQ(n.resumed()->profiles, 4u);
  }
  // A record intact by its checksum that is no profile: refused, the file named.
  std::filesystem::remove(dir / "state" / "profiles.rec");
  RecordLog log;
  ASSERT_TRUE(log.open((dir / "state" / "profiles.rec").string(), 0));
  ASSERT_TRUE(log.append("not a profile"));
  Feed f;
  try {
    MapperNode n(f.bus, config_in(dir), laser_on_mast(), {}, false, state);
    ADD_FAILURE() << "a damaged state was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("profiles.rec"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(MapperState, TheSegmentLogIsCompactedToTheNewestVersions) {
  const auto dir = fresh_dir("compact");
  MapperStateStore store((dir / "state").string(), 6.0);
  EXPECT_FALSE(store.load());
  TrajectorySegment s;
  s.key_id_first = 5;
  for (int i = 0; i < 1000; ++i) {
    s.utimes.push_back(kT0 + i * 1000);
    s.T_world_base.emplace_back(0.001 * i, 0, 0);
  }
  // 1000 poses are 32 KB a version: 200 versions are 6.4 MB without compaction.
  for (int rev = 0; rev < 200; ++rev) {
    s.T_world_base.back() = Pose2(1.0 + rev, 0, 0);
    store.record(s, rev);
  }
  EXPECT_GT(store.counters().compactions, 0);
  EXPECT_EQ(store.counters().write_failures, 0);
  EXPECT_LT(std::filesystem::file_size(dir / "state" / "segments.rec"), 2u * 32'000 + (1u << 20));
  MapperStateStore again((dir / "state").string(), 6.0);
  const auto saved = again.load();
  ASSERT_TRUE(saved);
  ASSERT_FALSE(saved->segments.empty());
  EXPECT_EQ(saved->segments.back().revision, 199);
  EXPECT_EQ(saved->segments.back().segment.T_world_base.back().x(), 200.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::mapper
