// The densifier and mapper nodes over memq://: frontend poses with an offset are bent onto the
// key poses, the corrected trajectory reaches the mapper as segments, profiles are placed with it,
// and a re-optimisation republishes only the moved segments and moves the mapper's points.
#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>
#include <octomap/ColorOcTree.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <numbers>
#include <tuple>

#include "channels.hpp"
#include "graph_fixture.hpp"
#include "ply.hpp"

namespace traverse {
namespace {

struct KeyLess {
  bool operator()(const octomap::OcTreeKey& a, const octomap::OcTreeKey& b) const {
    return std::tie(a[0], a[1], a[2]) < std::tie(b[0], b[1], b[2]);
  }
};


TEST_P(GraphTest, CorrectedTrajectoryPlacesProfilesAndFollowsReoptimisation) {
  // 2 s at 0.5 m/s; the frontend is 1 cm north of the truth, the key poses are the truth.
  drive(100, true);
  ASSERT_EQ(segments_.size(), 6u);  // keys 0..6 -> 6 segments
  for (const auto& s : segments_) EXPECT_EQ(s.revision, 0);
  ASSERT_EQ(dense_.size(), 91u);  // poses 0..90, each once, in order
  for (std::size_t i = 0; i < dense_.size(); ++i) {
    EXPECT_NEAR(dense_[i].y, 0.0, 1e-12);
    if (i > 0) {
      EXPECT_GT(dense_[i].utime, dense_[i - 1].utime);
    }
  }
  const std::size_t placed = mapper_->mapper().profiles();
  EXPECT_GE(placed, 29u);  // profiles up to the last closed segment (1.8 s)
  double max_y = -1e9;
  mapper_->mapper().for_each_point(
      [&](const mapper::CloudPoint& p) { max_y = std::max<double>(max_y, p.p_world.y()); });
  EXPECT_NEAR(max_y, 2.0, 1e-3);  // a 2 m circle across the path, around y = 0

  // Re-optimisation: key poses 5 and 6 move 5 cm north; segments 4-5 and 5-6 are sent again.
  segments_.clear();
  send_keys({5, 6}, 0.05);
  handle_all();
  ASSERT_EQ(segments_.size(), 2u);
  EXPECT_EQ(segments_[0].key_id_first, 4);
  EXPECT_EQ(segments_[1].key_id_first, 5);
  EXPECT_EQ(segments_[1].revision, 1);
  EXPECT_NEAR(segments_[1].y.front(), 0.05, 1e-12);
  EXPECT_EQ(dense_.size(), 91u);  // the growing trajectory is not sent again
  mapper_->flush();
  EXPECT_GT(mapper_->mapper().profiles_replaced(), 0);
  int moved = 0;
  mapper_->mapper().for_each_point([&](const mapper::CloudPoint& p) {
    if (p.utime >= kT0 + 5 * kKeyEvery * kPoseDt && p.p_world.y() > 2.04) ++moved;
  });
  EXPECT_GT(moved, 0);
  mapper_->report_counters();
  EXPECT_EQ(mapper_counters_["segments_applied"], 8);
  EXPECT_EQ(mapper_counters_["segments_stale"], 0);
  // Live, how far the map trailed the arrivals is measured per batch; inline nothing trails.
  if (GetParam()) {
    EXPECT_GT(mapper_counters_["map_lag_max_s"], 0.0);
    EXPECT_GE(mapper_counters_["map_lag_max_s"], mapper_counters_["map_lag_s"]);
  } else {
    EXPECT_EQ(mapper_counters_["map_lag_max_s"], 0.0);
  }
}

// A loop closure that moves 900 segments at once: they leave in a few messages, each under the
// configured size and all of one publish sharing utime, optimisation and a part count, and every
// one of them reaches the mapper. A repeated (stale) revision is counted and ignored.
TEST_P(GraphTest, BurstOfMovedSegmentsGoesOutInFewWholeMessages) {
  constexpr int kSegments = 900;
  drive(kSegments * kKeyEvery, false);
  ASSERT_EQ(segments_.size(), static_cast<std::size_t>(kSegments));
  const std::size_t messages_before = messages_.size();
  segments_.clear();
  messages_.clear();

  std::vector<int> all;
  for (int k = 0; k <= kSegments; ++k) all.push_back(k);
  send_keys(all, 0.05, 2);  // everything moves 5 cm north
  handle_all();
  mapper_->flush();
  ASSERT_EQ(segments_.size(), static_cast<std::size_t>(kSegments));
  // 16 poses of 32 bytes plus 28 bytes per segment: ~540 bytes, ~110 per 60 kB message.
  const int limit = densifier::DensifierConfig{}.max_message_bytes;
  ASSERT_GE(messages_.size(), 2u);
  EXPECT_LE(messages_.size(), 10u);
  for (std::size_t i = 0; i < messages_.size(); ++i) {
    const dense_segments_t& m = messages_[i];
    EXPECT_LE(m.getEncodedSize(), limit);
    EXPECT_EQ(m.part, static_cast<int32_t>(i));
    EXPECT_EQ(m.parts, static_cast<int32_t>(messages_.size()));
    EXPECT_EQ(m.optimisation, 2);
    EXPECT_EQ(m.utime, kT0 + kSegments * kKeyEvery * kPoseDt);    // newest frontend pose
    EXPECT_EQ(m.seq, static_cast<int64_t>(messages_before + i));  // numbered from 0
  }
  for (int k = 0; k < kSegments; ++k) {
    EXPECT_EQ(segments_[k].key_id_first, k);
    EXPECT_EQ(segments_[k].revision, 1);
  }
  mapper_->report_counters();
  EXPECT_EQ(mapper_counters_["segments_applied"], 2 * kSegments);
  EXPECT_EQ(mapper_counters_["segments_stale"], 0);
  EXPECT_EQ(bus_.stats().at(channels::kDenseSegments).missed, 0);

  // The same revisions again (e.g. a duplicated message) change nothing and count as stale.
  dense_segments_t again = messages_.front();
  bus_.publish(channels::kDenseSegments, again);
  handle_all();
  mapper_->report_counters();
  EXPECT_EQ(mapper_counters_["segments_applied"], 2 * kSegments);
  EXPECT_EQ(mapper_counters_["segments_stale"], again.n_segments);
}

// Occupied leaves of `a` that are not occupied in `b` (by key at the finest level).
int occupied_missing(const octomap::OcTree& a, const octomap::OcTree& b) {
  int missing = 0;
  for (auto it = a.begin_leafs(), end = a.end_leafs(); it != end; ++it) {
    if (!a.isNodeOccupied(*it)) continue;
    const octomap::OcTreeNode* n = b.search(it.getCoordinate());
    if (!n || !b.isNodeOccupied(n)) ++missing;
  }
  return missing;
}

// The exports after a move: the PLY reads back point for point, and OctoMap's own tool
// (convert_octree of octomap-tools) reads map.bt and map.ot into the same occupied voxels.
TEST_P(GraphTest, ExportsReadBackThroughThePlyReaderAndOctoMapsOwnTool) {
  drive(100, true);
  send_keys({5, 6}, 0.05);
  handle_all();
  mapper_->flush();
  std::string error;
  ASSERT_TRUE(mapper_->export_all(&error)) << error;
  const mapper::Mapper& m = mapper_->mapper();
  auto cloud = mapper::read_ply((out_dir_ / "cloud.ply").string(), &error);
  ASSERT_TRUE(cloud) << error;
  ASSERT_EQ(static_cast<int64_t>(cloud->size()), m.placed_points());
  std::size_t i = 0;
  m.for_each_point(
      [&](const mapper::CloudPoint& p) { EXPECT_EQ((*cloud)[i++].p_world, p.p_world); });
  EXPECT_GT(m.occupied_voxels(), 100u);
  for (const std::string name : {"map.bt", "map.ot"}) {
    const auto converted = out_dir_ / (name + ".converted.ot");
    const std::string cmd = "convert_octree " + (out_dir_ / name).string() + " " +
                            converted.string() + " > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << " (octomap-tools: scripts/setup.sh)";
    std::unique_ptr<octomap::AbstractOcTree> read(
        octomap::AbstractOcTree::read(converted.string()));
    const auto* tree = dynamic_cast<const octomap::OcTree*>(read.get());
    ASSERT_NE(tree, nullptr) << converted;
    EXPECT_EQ(tree->getResolution(), m.octree().getResolution());
    EXPECT_EQ(occupied_missing(m.octree(), *tree), 0) << name;
    EXPECT_EQ(occupied_missing(*tree, m.octree()), 0) << name;
  }
}

// The annotator's colours in the export: each point takes the level and colour of the key pose
// nearest in time, and the newest annotation of a key pose wins (a loop closure recolours); each
// voxel of the coloured OctoMap takes the worst level of its points.
TEST_P(GraphTest, ExportColoursPointsByTheNewestAnnotationOfTheirKeyPose) {
  drive(100, true);
  auto annotate = [&](const std::vector<int>& ids, int8_t level, uint8_t red, uint8_t green) {
    annotations_t msg{};
    msg.utime = kT0 + ids.back() * kKeyEvery * kPoseDt;
    msg.parts = 1;
    for (int k : ids) {
      key_annotation_t a{};
      a.utime = kT0 + k * kKeyEvery * kPoseDt;
      a.id = k;
      a.level = level;
      a.rgb[0] = red;
      a.rgb[1] = green;
      msg.keys.push_back(a);
    }
    msg.n_keys = static_cast<int32_t>(msg.keys.size());
    bus_.publish(channels::kAnnotations, msg);
    handle_all();
  };
  annotate({0, 1, 2, 3, 4, 5, 6}, 1, 0, 255);
  annotate({0, 1}, 4, 255, 0);  // the first two key poses turn red
  std::string error;
  ASSERT_TRUE(mapper_->export_all(&error)) << error;
  auto cloud = mapper::read_ply((out_dir_ / "cloud.ply").string(), &error);
  ASSERT_TRUE(cloud) << error;
  ASSERT_GT(cloud->size(), 100u);
  int red = 0, green = 0;
  for (const mapper::CloudPoint& p : *cloud) {
    // Nearest key pose by time: key k covers times within half a key interval of it.
    const double k = static_cast<double>(p.utime - kT0) / (kKeyEvery * kPoseDt);
    const bool near_first_two = k <= 1.5;  // a tie goes to the earlier key pose
    EXPECT_EQ(p.colour.level, near_first_two ? 4 : 1) << k;
    EXPECT_EQ(p.colour.rgb[0], near_first_two ? 255 : 0) << k;
    (near_first_two ? red : green)++;
  }
  EXPECT_GT(red, 0);
  EXPECT_GT(green, red);
  // map_colour.ot: each occupied voxel in the colour of the worst level of the PLY points in it.
  std::unique_ptr<octomap::AbstractOcTree> read(
      octomap::AbstractOcTree::read((out_dir_ / "map_colour.ot").string()));
  const auto* tree = dynamic_cast<const octomap::ColorOcTree*>(read.get());
  ASSERT_NE(tree, nullptr);
  std::map<octomap::OcTreeKey, mapper::PointColour, KeyLess> worst;
  for (const mapper::CloudPoint& p : *cloud) {
    const octomap::OcTreeKey key = tree->coordToKey(p.p_world.x(), p.p_world.y(), p.p_world.z());
    auto [it, inserted] = worst.try_emplace(key, p.colour);
    if (!inserted && p.colour.level > it->second.level) it->second = p.colour;
  }
  int red_voxels = 0;
  for (const auto& [key, colour] : worst) {
    const octomap::ColorOcTreeNode* node = tree->search(key);
    ASSERT_NE(node, nullptr);
    ASSERT_TRUE(tree->isNodeOccupied(node));
    EXPECT_EQ(node->getColor(),
              octomap::ColorOcTreeNode::Color(colour.rgb[0], colour.rgb[1], colour.rgb[2]));
    red_voxels += colour.level == 4;
  }
  EXPECT_GT(red_voxels, 0);
  EXPECT_EQ(worst.size(), mapper_->mapper().occupied_voxels());
  mapper_->report_counters();
  EXPECT_EQ(mapper_counters_.at("voxels_coloured"), static_cast<double>(worst.size()));
  EXPECT_EQ(mapper_counters_.at("voxels_annotated"), static_cast<double>(worst.size()));
  EXPECT_EQ(mapper_counters_.at("annotation_level_changes"), 2.0);
  EXPECT_EQ(mapper_counters_.at("annotated_key_poses"), 7.0);
}

// The preview goes out in the order profiles are first placed, which is not their time order: a
// profile that reaches back into a segment a loop closure just moved is placed with the moves,
// after newer profiles. CLOUD_PREVIEW's time still never goes backwards (the monitor calls that a
// fault), and each profile keeps its own time.
class OnePointPreviewTest : public GraphTest {
 protected:
  void configure(mapper::MapperConfig& c) override { c.preview.max_points_per_message = 1; }
};

TEST_P(OnePointPreviewTest, PreviewTimeNeverGoesBackWhenAMovePlacesAnOlderProfileLast) {
  std::vector<cloud_preview_t> preview;  // every message, in any order (the order is checked here)
  bus_.subscribe<cloud_preview_t>(
      channels::kCloudPreview, [&](const cloud_preview_t& m) { preview.push_back(m); }, true);
  drive(3 * kKeyEvery, true);  // key poses 0-3; segment 2 (to key pose 3) closed
  mapper_->publish_preview();
  handle_all();
  // Poses up to key pose 4 and profiles from just before key pose 3 on (30 ms long: the first
  // spans it), all waiting for segment 3; then key pose 3 moves and key pose 4 arrives in one
  // optimisation: segment 2 moves, segment 3 closes.
  for (int i = 3 * kKeyEvery + 1; i <= 4 * kKeyEvery; ++i) send_frontend_pose(i);
  for (int i = 3 * kKeyEvery - 1; i + 2 <= 4 * kKeyEvery; i += 3) send_profile(kT0 + i * kPoseDt);
  handle_all();
  mapper_->flush();
  send_keys({3, 4}, 0.05);
  handle_all();
  mapper_->flush();
  mapper_->publish_preview();
  handle_all();
  // The profile across key pose 3 touches the moved segment: it went out after the newer ones.
  int64_t newest_profile = 0;
  bool older_after_newer = false;
  for (const cloud_preview_t& m : preview) {
    for (const preview_profile_t& p : m.profiles) {
      older_after_newer = older_after_newer || p.utime < newest_profile;
      newest_profile = std::max(newest_profile, p.utime);
    }
  }
  ASSERT_TRUE(older_after_newer);
  for (std::size_t i = 1; i < preview.size(); ++i) {
    EXPECT_GE(preview[i].utime, preview[i - 1].utime) << "message " << i;
  }
  for (const cloud_preview_t& m : preview) {
    for (const preview_profile_t& p : m.profiles) EXPECT_LE(p.utime, m.utime);
  }
}

// Inline (replay): one message at a time, so the closure's message alone moves segment 2 and
// closes segment 3 (the worker batches messages as they come).
INSTANTIATE_TEST_SUITE_P(Mapper, OnePointPreviewTest, ::testing::Values(false),
                         [](const auto&) { return "inline"; });

INSTANTIATE_TEST_SUITE_P(Mapper, GraphTest, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "worker" : "inline"; });

}  // namespace
}  // namespace traverse
