#include "voxel_colours.hpp"

#include <unordered_map>

namespace traverse::mapper {

std::unique_ptr<octomap::ColorOcTree> coloured_octree(const Mapper& mapper,
                                                      const PointColours& colours,
                                                      VoxelColourCounts* counts) {
  const octomap::OcTree& tree = mapper.octree();
  // Worst level per voxel: levels are legend indices, best first, so the worst is the largest;
  // an unannotated point (-1) loses to any annotated one.
  std::unordered_map<octomap::OcTreeKey, PointColour, octomap::OcTreeKey::KeyHash> worst;
  mapper.for_each_point([&](const CloudPoint& p) {
    octomap::OcTreeKey key;
    if (!tree.coordToKeyChecked(p.p_world.x(), p.p_world.y(), p.p_world.z(), key)) return;
    const PointColour c = colours.at(p.utime);
    auto [it, inserted] = worst.try_emplace(key, c);
    if (!inserted && c.level > it->second.level) it->second = c;
  });
  auto out = std::make_unique<octomap::ColorOcTree>(tree.getResolution());
  VoxelColourCounts n;
  // The mapper sets its voxels lazily and never prunes or deletes a node (mapper.hpp), so every
  // leaf is a finest-level voxel.
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey key = it.getKey();
    out->setNodeValue(key, it->getLogOdds(), true);
    if (!tree.isNodeOccupied(*it)) continue;
    const auto w = worst.find(key);
    const PointColour c = w == worst.end() ? PointColour{} : w->second;
    out->setNodeColor(key, c.rgb[0], c.rgb[1], c.rgb[2]);
    ++n.voxels;
    if (c.level >= 0) ++n.annotated;
  }
  out->updateInnerOccupancy();
  if (counts) *counts = n;
  return out;
}

}  // namespace traverse::mapper
