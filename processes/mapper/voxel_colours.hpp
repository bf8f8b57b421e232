// The OctoMap coloured by accuracy level (seed 004's colours on voxels, not only on points): an
// octomap::ColorOcTree with the occupancy of the mapper's OctoMap, each occupied voxel in the
// colour of the WORST level among the points in it (point_colours.hpp gives each point the level
// of the key pose nearest in time). Worst, not newest: a voxel seen on the way out and again after
// a long unclosed loop holds points placed from both passes, and a surveyor checking a wall
// against the map must not be shown the better of two estimates that disagree; the worst level is
// also the same whatever order the points come in. A voxel whose points have no annotation yet
// stays grey (128, 128, 128); free voxels keep ColorOcTree's default white.
#pragma once

#include <octomap/ColorOcTree.h>

#include <memory>

#include "mapper.hpp"
#include "point_colours.hpp"

namespace traverse::mapper {

struct VoxelColourCounts {
  int64_t voxels = 0;     // occupied voxels coloured
  int64_t annotated = 0;  // ... of which from an annotated point (the others grey)
};

// A ColorOcTree of the same resolution and leaves (log-odds) as mapper.octree(), occupied voxels
// coloured as above; inner nodes updated, ready to write (.ot, ColorOcTree::write).
std::unique_ptr<octomap::ColorOcTree> coloured_octree(const Mapper& mapper,
                                                      const PointColours& colours,
                                                      VoxelColourCounts* counts = nullptr);

}  // namespace traverse::mapper
