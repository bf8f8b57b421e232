// The coloured OctoMap (voxel_colours.hpp): written as a ColorOcTree, read back with OctoMap's own
// reader, every occupied voxel in the colour of the worst accuracy level of the points in it,
// whatever the order of the annotations; free of annotations, grey.
#include "voxel_colours.hpp"

#include <gtest/gtest.h>
#include <octomap/AbstractOcTree.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <map>
#include <numbers>

namespace traverse::mapper {
namespace {

constexpr int64_t kVoxelT0 = 1'600'000'000'000'000;
constexpr std::array<uint8_t, 3> kGreen{0, 200, 0}, kOrange{255, 128, 0}, kRed{230, 0, 0};

// The cart stands at A (1, 2) until 300 ms, then at B, 20 m east, from 400 ms on.
TrajectorySegment standing_then_moved() {
  TrajectorySegment s;
  s.key_id_first = 0;
  for (int i = 0; i <= 80; ++i) {
    const int64_t t = kVoxelT0 + i * 10'000;
    s.utimes.push_back(t);
    s.T_world_base.push_back(t <= kVoxelT0 + 300'000 ? Pose2(1.0, 2.0, 0.3) : Pose2(21.0, 2.0, 0.3));
  }
  return s;
}

// A vertical half circle of 2 m returns (the scanner looks up and sideways), 20 ms long.
Profile arc(int64_t t0) {
  Profile p;
  p.utime_first = t0;
  p.utime_last = t0 + 20'000;
  p.angle_first = 0.0f;
  p.angle_step = static_cast<float>(std::numbers::pi / 180);
  p.ranges.assign(181, 2.0f);
  return p;
}

class VoxelColours : public ::testing::Test {
 protected:
  VoxelColours() : mapper_(config(), extrinsic()) {
    mapper_.set_segment(standing_then_moved());
    mapper_.add_profile(arc(kVoxelT0));            // at A, nearest key pose 0
    mapper_.add_profile(arc(kVoxelT0 + 200'000));  // at A again, nearest key pose 1
    mapper_.add_profile(arc(kVoxelT0 + 600'000));  // at B, nearest key pose 2
  }
  static MapperConfig config() {
    MapperConfig c;
    c.footprint = {-0.1, 0.1, -0.1, 0.1, 0.02, 0.5};
    return c;
  }
  static Eigen::Isometry3d extrinsic() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.3, 0.0, 1.0);
    return T;
  }
  // Writes the coloured tree and reads it back through OctoMap's factory.
  std::unique_ptr<octomap::AbstractOcTree> round_trip(const PointColours& colours,
                                                      VoxelColourCounts& counts) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("traverse_voxel_colours_" + std::to_string(::getpid()) + ".ot");
    EXPECT_TRUE(coloured_octree(mapper_, colours, &counts)->write(path.string()));
    std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(path.string()));
    std::filesystem::remove(path);
    return tree;
  }
  // Colour of every occupied leaf, by the x of its centre: A's voxels lie west of x = 11 m.
  static std::map<std::string, std::array<uint8_t, 3>> colours_by_side(
      const octomap::ColorOcTree& tree, int& occupied, int& mixed) {
    std::map<std::string, std::array<uint8_t, 3>> out;
    occupied = mixed = 0;
    for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
      if (!tree.isNodeOccupied(*it)) continue;
      ++occupied;
      const octomap::ColorOcTreeNode::Color c = it->getColor();
      const std::array<uint8_t, 3> rgb{c.r, c.g, c.b};
      const std::string side = it.getX() < 11.0 ? "A" : "B";
      auto [at, inserted] = out.try_emplace(side, rgb);
      if (!inserted && at->second != rgb) ++mixed;
    }
    return out;
  }
  Mapper mapper_;
};

TEST_F(VoxelColours, EachVoxelTakesTheWorstLevelOfItsPoints) {
  // The same voxels at A from key poses 0 and 1; the worse of the two wins, in either order.
  for (const bool worse_first : {false, true}) {
    PointColours colours;
    colours.set(0, kVoxelT0, worse_first ? 3 : 1, worse_first ? kOrange : kGreen);
    colours.set(1, kVoxelT0 + 200'000, worse_first ? 1 : 3, worse_first ? kGreen : kOrange);
    colours.set(2, kVoxelT0 + 600'000, 4, kRed);
    VoxelColourCounts counts;
    const auto read = round_trip(colours, counts);
    const auto* tree = dynamic_cast<const octomap::ColorOcTree*>(read.get());
    ASSERT_NE(tree, nullptr);
    EXPECT_EQ(tree->getResolution(), mapper_.octree().getResolution());
    int occupied = 0, mixed = 0;
    const auto side = colours_by_side(*tree, occupied, mixed);
    EXPECT_EQ(occupied, static_cast<int>(mapper_.occupied_voxels()));
    EXPECT_GT(occupied, 100);
    EXPECT_EQ(counts.voxels, occupied);
    EXPECT_EQ(counts.annotated, occupied);
    EXPECT_EQ(mixed, 0);
    EXPECT_EQ(side.at("A"), kOrange) << worse_first;
    EXPECT_EQ(side.at("B"), kRed) << worse_first;
  }
}

TEST_F(VoxelColours, VoxelsWithoutAnnotationsAreGrey) {
  VoxelColourCounts counts;
  const auto read = round_trip(PointColours{}, counts);
  const auto* tree = dynamic_cast<const octomap::ColorOcTree*>(read.get());
  ASSERT_NE(tree, nullptr);
  int occupied = 0, mixed = 0;
  const auto side = colours_by_side(*tree, occupied, mixed);
  EXPECT_EQ(counts.annotated, 0);
  EXPECT_EQ(counts.voxels, occupied);
  const std::array<uint8_t, 3> grey{128, 128, 128};
  EXPECT_EQ(side.at("A"), grey);
  EXPECT_EQ(side.at("B"), grey);
  EXPECT_EQ(mixed, 0);
}

}  // namespace
}  // namespace traverse::mapper
