// The frontend's map: occupancy grids of resolution r, 2r, 4r, ... (Hector SLAM section IV.D,
// level 0 the finest), all updated with every scan.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "frontend_config.hpp"
#include "occupancy_grid.hpp"
#include "se2.hpp"

namespace traverse::frontend {

class MapPyramid {
 public:
  explicit MapPyramid(const MapConfig& config);
  int levels() const { return static_cast<int>(grids_.size()); }
  const OccupancyGrid& level(int k) const { return grids_[k]; }
  // Integrates a scan: hits in the base frame, seen from T_map_base * origin_base.
  void update(const Pose2& T_map_base, const Eigen::Vector2d& origin_base,
              const std::vector<Eigen::Vector2d>& hits_base);
  std::size_t memory_bytes() const;
  // Drops far tiles (all levels) so the total stays under max_bytes. Returns tiles dropped.
  std::size_t bound_memory(const Eigen::Vector2d& p_map, std::size_t max_bytes);
  // The journal of every level (OccupancyGrid::begin_journal): updates made while it is open
  // can be undone exactly (rollback(), which ends it) or kept (end_journal()).
  void begin_journal();
  void rollback();
  void end_journal();

 private:
  std::vector<OccupancyGrid> grids_;
};

}  // namespace traverse::frontend
