#include "map_pyramid.hpp"

#include <cmath>

namespace traverse::frontend {

MapPyramid::MapPyramid(const MapConfig& config) {
  for (int k = 0; k < std::max(1, config.levels); ++k) {
    grids_.emplace_back(config.resolution_m * std::ldexp(1.0, k), config.p_occupied, config.p_free,
                        config.subcell_hits);
  }
}

void MapPyramid::update(const Pose2& T_map_base, const Eigen::Vector2d& origin_base,
                        const std::vector<Eigen::Vector2d>& hits_base) {
  std::vector<Eigen::Vector2d> hits_map;
  hits_map.reserve(hits_base.size());
  for (const auto& p : hits_base) hits_map.push_back(T_map_base * p);
  const Eigen::Vector2d origin_map = T_map_base * origin_base;
  // Incidence of each beam on the surface it hit, the surface's direction taken from the two
  // neighbouring points of the scan. Far apart neighbours are what a grazing beam produces; at a
  // depth jump the "tangent" runs along the beam and also reads as grazing: the free-space update
  // then stops early, the cautious side.
  std::vector<double> incidence_sin(hits_base.size(), 1.0);
  for (std::size_t i = 1; i + 1 < hits_base.size(); ++i) {
    const Eigen::Vector2d tangent = hits_base[i + 1] - hits_base[i - 1];
    const double length = tangent.norm();
    if (length <= 0.0) continue;
    const Eigen::Vector2d ray = (hits_base[i] - origin_base).normalized();
    incidence_sin[i] = std::abs(ray.x() * tangent.y() - ray.y() * tangent.x()) / length;
  }
  for (auto& grid : grids_) grid.update(origin_map, hits_map, &incidence_sin);
}

std::size_t MapPyramid::memory_bytes() const {
  std::size_t bytes = 0;
  for (const auto& grid : grids_) bytes += grid.memory_bytes();
  return bytes;
}

std::size_t MapPyramid::bound_memory(const Eigen::Vector2d& p_map, std::size_t max_bytes) {
  // Each level gets a share of the budget in proportion to what it holds now.
  const std::size_t total = memory_bytes();
  if (total <= max_bytes) return 0;
  std::size_t dropped = 0;
  for (auto& grid : grids_) {
    const double share = static_cast<double>(grid.memory_bytes()) / static_cast<double>(total);
    dropped += grid.evict_farthest(p_map, static_cast<std::size_t>(share * max_bytes));
  }
  return dropped;
}

void MapPyramid::begin_journal() {
  for (auto& grid : grids_) grid.begin_journal();
}

void MapPyramid::rollback() {
  for (auto& grid : grids_) grid.rollback();
}

void MapPyramid::end_journal() {
  for (auto& grid : grids_) grid.end_journal();
}

}  // namespace traverse::frontend
