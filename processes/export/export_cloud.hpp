// The cloud products of traverse-export: reads the mapper's binary PLY point by point (any layout
// with float x, y, z and the optional intensity, time and key_id properties, so added properties
// do not break it), moves each point into the output frame, gives it the accuracy level and
// colour of its key poses (products.hpp), keeps every n-th point when thinning, and writes LAS
// 1.4 (common/las_writer.hpp) and a binary PLY with colours and levels.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "products.hpp"

namespace traverse::exporter {

struct CloudPoint {
  double x = 0, y = 0, z = 0;  // [m]
  double intensity = 0;        // [0..255]
  double time_s = 0;           // [s] since the Unix epoch
  int64_t key_id = -1;         // key pose whose segment placed it (-1: not in the file)
};

// Calls `each` for every point of a little-endian binary PLY with x, y, z; returns the count, or
// -1 with `error` set.
int64_t read_ply_points(const std::string& path, const std::function<void(const CloudPoint&)>& each,
                        std::string* error);

struct CloudOptions {
  std::string las_path, ply_path;  // either may be empty (not written)
  std::string frame = "map";
  Pose2 T_out_map;                        // map frame -> output frame (identity for "map")
  int thin_every = 1;                     // keep every n-th point
  int top_level = 40, bottom_level = 20;  // LOA levels for the colours (seed 004)
};

struct CloudSummary {
  int64_t read = 0, written = 0;
  std::map<int, int64_t> points_per_level;  // LOA level -> points written
};

// 95 % bound [m] at a point's time from its segment's two key poses (interpolated), by key id.
class PointBounds {
 public:
  explicit PointBounds(const RunEstimate& run);
  double at(int64_t key_id, double time_s) const;

 private:
  struct Span {
    double t0 = 0, t1 = 0, b0 = 0, b1 = 0;
  };
  std::map<int64_t, Span> by_first_;
};

// Writes the requested files; false with `error` set on failure.
bool export_cloud(const std::string& ply_in, const RunEstimate& run, const CloudOptions& options,
                  CloudSummary* summary, std::string* error);

// OGC WKT of a local frame named `frame` (metres), for the LAS file.
std::string local_frame_wkt(const std::string& frame);

}  // namespace traverse::exporter
