#include "preview_thinning.hpp"

#include <algorithm>
#include <cmath>

#include "preview.hpp"

namespace traverse::mapper {

namespace {

// A point during a pass: its cell, its rank in time order over all points and its profile's.
struct Cell {
  uint64_t key = 0;  // preview_cell() at the pass's grid
  uint32_t order = 0;
  uint32_t profile = 0;
};

// Of the points of each cell, keeps the earliest (leaves `cells` sorted by cell).
void keep_earliest(std::vector<Cell>& cells) {
  std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) {
    return a.key < b.key || (a.key == b.key && a.order < b.order);
  });
  cells.erase(std::unique(cells.begin(), cells.end(),
                          [](const Cell& a, const Cell& b) { return a.key == b.key; }),
              cells.end());
}

// [bytes] what `profiles` profiles would hold with only `cells` kept.
int64_t bytes_of(const std::vector<Cell>& cells, std::size_t profiles) {
  std::vector<bool> has_point(profiles);
  int64_t kept = 0;
  for (const Cell& c : cells) {
    if (!has_point[c.profile]) {
      has_point[c.profile] = true;
      ++kept;
    }
  }
  return static_cast<int64_t>(cells.size()) * kKeptPointBytes + kept * kKeptProfileBytes;
}

void drop_all_but(const std::vector<Cell>& cells, std::size_t points, KeptProfiles& kept) {
  std::vector<bool> keep(points);
  for (const Cell& c : cells) keep[c.order] = true;
  std::size_t order = 0;
  for (auto it = kept.begin(); it != kept.end();) {
    KeptProfile& k = it->second;
    std::size_t n = 0;
    for (const std::array<int16_t, 3>& q : k.p_base_mm) {
      if (keep[order++]) k.p_base_mm[n++] = q;
    }
    k.p_base_mm.resize(n);
    if (n == 0) {
      it = kept.erase(it);
      continue;
    }
    k.p_base_mm.shrink_to_fit();
    ++it;
  }
}

}  // namespace

double thin_earliest_per_cell(KeptProfiles& kept, double cell_m, int64_t max_bytes) {
  std::size_t points = 0;
  for (const auto& [utime, k] : kept) points += k.p_base_mm.size();
  std::vector<Cell> cells;
  cells.reserve(points);
  uint32_t order = 0, profile = 0;
  for (const auto& [utime, k] : kept) {
    const double c = std::cos(k.theta), s = std::sin(k.theta);
    for (const std::array<int16_t, 3>& q : k.p_base_mm) {
      const double bx = q[0] * 1e-3, by = q[1] * 1e-3;
      const std::optional<uint64_t> cell =
          preview_cell(k.x + c * bx - s * by, k.y + s * bx + c * by, q[2] * 1e-3, cell_m);
      if (cell) cells.push_back({*cell, order, profile});
      ++order;
    }
    ++profile;
  }
  keep_earliest(cells);
  // Cells of twice the edge are unions of eight: their keys follow from the ones at hand.
  while (bytes_of(cells, kept.size()) > max_bytes / 2 && cell_m < 1e3) {
    cell_m *= 2.0;
    for (Cell& c : cells) c.key = preview_cell_doubled(c.key);
    keep_earliest(cells);
  }
  drop_all_but(cells, points, kept);
  return cell_m;
}

}  // namespace traverse::mapper
