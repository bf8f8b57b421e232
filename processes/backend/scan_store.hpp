// Key scans of the backend, kept in memory at reduced density.
//
// A key scan is converted once to points in the base frame of its key pose: every beam is placed
// with the pose at its own time (motion during the sweep undone with the frontend's trajectory,
// as seed 000 does for Hector), then the points are thinned along the sweep so that consecutive
// kept points are at least `point_spacing_m` apart. The matcher blurs its table by a few
// centimetres anyway, so nothing finer is needed. Points are stored as float pairs (8 bytes): on
// the simulated office routes (0.05 m spacing, 20 m range) a key scan keeps about 900 points,
// 7.1 KB per key pose (the status counter scan_bytes_per_key_pose reports the live figure),
// against 43 KB for the raw sweep: an hour at three key poses per second holds about 77 MB.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "planar_scan.hpp"
#include "se2.hpp"

namespace traverse::backend {

using PlanarScan = ::traverse::PlanarScan;

struct ScanStoreConfig {
  double point_spacing_m = 0.05;  // minimum distance between consecutive kept points [m]
  double min_range_m = 0.3;       // readings closer than this are dropped (the cart itself) [m]
  double max_range_m = 20.0;      // readings farther than this are dropped [m]

  template <class V>
  void visit(V& v) {
    v("point_spacing_m", point_spacing_m);
    v("min_range_m", min_range_m);
    v("max_range_m", max_range_m);
  }
};

std::optional<std::string> validate(const ScanStoreConfig& config);

// Points of `scan` in the base frame at time utime_ref: beam i is placed with
// T_ref_base(t_i) * T_base_laser, where T_ref_base(t) is the motion of the base relative to its
// pose at utime_ref. Thinned as described above.
std::vector<Eigen::Vector2f> reduce_scan(const PlanarScan& scan, const Pose2& T_base_laser,
                                         const std::function<Pose2(int64_t)>& T_ref_base,
                                         const ScanStoreConfig& config);

class ScanStore {
 public:
  // Stores the points of one key scan; returns its index (the key pose index).
  int add(std::vector<Eigen::Vector2f> points_base);
  int size() const { return static_cast<int>(scans_.size()); }
  const std::vector<Eigen::Vector2f>& points(int index) const { return scans_[index]; }
  // Points of scan `index` moved into the world frame by T_world_base, appended to `out`.
  void append_world(int index, const Pose2& T_world_base, std::vector<Eigen::Vector2d>& out) const;
  // Points as doubles in the base frame (the matcher's query).
  std::vector<Eigen::Vector2d> points_d(int index) const;

  // Heap memory held by the stored points [bytes], and per key pose on average [bytes].
  std::size_t memory_bytes() const { return bytes_; }
  double bytes_per_key_pose() const;

 private:
  std::vector<std::vector<Eigen::Vector2f>> scans_;
  std::size_t bytes_ = 0;
};

}  // namespace traverse::backend
