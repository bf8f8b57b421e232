// The thinning pass of what the mapper keeps for a late viewer (preview_resend.hpp): of the
// points in one cell of a grid, the earliest is kept (so the start of the route stays as it was);
// first at the current grid (what came since the last pass), then on a grid twice as coarse while
// more than half the cap is left.
//
// One flat array of every point's cell, sorted by cell then time: the first of each run of a cell
// is its earliest point. The hash set of cells this replaced cost an allocation a point (0.51 s
// for a full 8 MiB store at load 4, against 0.28 s; docs/late-joining.md). A pass touches only
// what it is given, so it can run on a thread of its own.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <vector>

namespace traverse::mapper {

// A profile kept: the pose it was first placed with (chooses its points' cells) and its points.
struct KeptProfile {
  float x = 0, y = 0, theta = 0;                  // [m, m, rad] the first placement's pose
  std::vector<std::array<int16_t, 3>> p_base_mm;  // [mm] base frame at the profile's utime
};
using KeptProfiles = std::map<int64_t, KeptProfile>;  // by utime [us]

// What a kept point costs [bytes] (three int16), and a kept profile besides its points (its map
// node and record).
inline constexpr int64_t kKeptPointBytes = 6;
inline constexpr int64_t kKeptProfileBytes = 96;

// Thins `kept` (at most 2^32 points) at `cell_m` [m], then at twice the cell while it holds more
// than `max_bytes` / 2; profiles left with no point are removed. Returns the grid it ends at [m].
double thin_earliest_per_cell(KeptProfiles& kept, double cell_m, int64_t max_bytes);

}  // namespace traverse::mapper
