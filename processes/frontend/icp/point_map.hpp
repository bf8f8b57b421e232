// The ICP frontend's map: points of key scans with their normals in the map frame, at most one
// per point_spacing_m, in a hash of square cells (as kiss-icp's voxel hash map, in 2D). The first
// point seen at a place stays: a pass that comes back matches against the map the first pass
// made, which is what keeps the trajectory from drifting on revisits (as Hector's grid does).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

namespace traverse::frontend {

struct MapPoint {
  Eigen::Vector2d p;  // [m] map frame
  Eigen::Vector2d n;  // unit normal, map frame
};

class PointMap {
 public:
  PointMap(double cell_m, double point_spacing_m);

  // Adds points (map frame) with their normals; a point within point_spacing_m of one already in
  // its cell is left out. Returns the points added.
  int add(const std::vector<MapPoint>& points);
  // The nearest map point within max_distance_m (at most cell_m: the point's cell and its
  // neighbours are searched).
  const MapPoint* nearest(const Eigen::Vector2d& q, double max_distance_m) const;
  // Drops the cells whose centre lies farther than radius_m from `centre`; returns how many.
  int64_t drop_beyond(const Eigen::Vector2d& centre, double radius_m);

  std::size_t points() const { return points_; }
  std::size_t memory_bytes() const;
  bool empty() const { return points_ == 0; }

 private:
  using Key = int64_t;
  Key key(int64_t ix, int64_t iy) const { return (ix << 32) ^ (iy & 0xffffffff); }
  int64_t index(double v) const { return static_cast<int64_t>(std::floor(v / cell_m_)); }

  double cell_m_, spacing2_;
  std::unordered_map<Key, std::vector<MapPoint>> cells_;
  std::size_t points_ = 0;
};

// Unit normals of points ordered along a scan, from their neighbours along it within radius_m
// (a line fitted by the spread of the neighbours); nullopt where fewer than 3 neighbours or no
// line (smallest spread over largest above max_spread).
std::vector<std::optional<Eigen::Vector2d>> scan_normals(const std::vector<Eigen::Vector2d>& points,
                                                         double radius_m, double max_spread);

}  // namespace traverse::frontend
