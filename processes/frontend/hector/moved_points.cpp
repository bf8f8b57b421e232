#include "moved_points.hpp"

#include <cmath>

namespace traverse::frontend {

std::vector<bool> seen_through(const OccupancyGrid& grid,
                               const std::vector<Eigen::Vector2d>& points_base,
                               const Pose2& T_map_base, double max_probability) {
  std::vector<bool> flags(points_base.size(), false);
  const double r = grid.resolution();
  for (std::size_t i = 0; i < points_base.size(); ++i) {
    const Eigen::Vector2d q = T_map_base * points_base[i];
    const int64_t ix = std::llround(q.x() / r), iy = std::llround(q.y() / r);
    bool free = true;
    for (int64_t dy = -1; dy <= 1 && free; ++dy) {
      for (int64_t dx = -1; dx <= 1 && free; ++dx) {
        free = grid.cell_probability(ix + dx, iy + dy) < max_probability;
      }
    }
    flags[i] = free;
  }
  return flags;
}

}  // namespace traverse::frontend
