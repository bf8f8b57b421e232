// Binary PLY (little endian) for the mapper's cloud: x, y, z [m, float32] in the map frame (the
// base at the first scan, or the frontend's initial_pose; traverse-export writes other frames),
// intensity [0..255, uchar], time [s since the Unix epoch, float64], key_id [int32, the key pose
// whose segment placed the point], red, green, blue [0..255, uchar] and level [char, the accuracy
// level index of the annotations, -1 for none] (point_colours.hpp). Opens in CloudCompare and
// other PLY readers; the reader below reads back exactly this layout (for the evaluation tools).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mapper.hpp"
#include "point_colours.hpp"

namespace traverse::mapper {

// Writes `count` points produced by `each` (which calls its argument once per point). Returns
// false if the file cannot be written or the count did not match.
bool write_ply(const std::string& path, int64_t count,
               const std::function<void(const std::function<void(const CloudPoint&)>&)>& each);

// Writes the mapper's whole cloud, each point coloured by `colours` when given.
bool write_ply(const std::string& path, const Mapper& mapper,
               const PointColours* colours = nullptr);

// Reads a file written by write_ply; nullopt (with `error` set) on any other layout.
std::optional<std::vector<CloudPoint>> read_ply(const std::string& path, std::string* error);

}  // namespace traverse::mapper
