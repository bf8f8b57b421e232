#include "occupancy_grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace traverse::frontend {
namespace {

constexpr double kLogOddsStep = 0.05;  // log-odds per stored integer step: range +-6.35
constexpr int kLogOddsMax = 127;

int log_odds_steps(double p) {
  return static_cast<int>(std::lround(std::log(p / (1.0 - p)) / kLogOddsStep));
}

int64_t floor_div_tile(int64_t i) { return i >> OccupancyGrid::kTileBits; }  // arithmetic shift
int64_t in_tile(int64_t i) { return i & (OccupancyGrid::kTileSize - 1); }
// Cells (x0..x0+1, y0..y0+1) all in one tile.
bool in_one_tile(int64_t x0, int64_t y0) {
  return in_tile(x0) < OccupancyGrid::kTileSize - 1 && in_tile(y0) < OccupancyGrid::kTileSize - 1;
}

}  // namespace

OccupancyGrid::OccupancyGrid(double resolution_m, double p_occupied, double p_free, bool subcell)
    : resolution_m_(resolution_m),
      subcell_(subcell),
      occupied_delta_(log_odds_steps(p_occupied)),
      free_delta_(log_odds_steps(p_free)) {
  for (int l = -128; l < 128; ++l) {
    probability_of_[l + 128] = static_cast<float>(1.0 / (1.0 + std::exp(-l * kLogOddsStep)));
  }
}

uint64_t OccupancyGrid::tile_key(int64_t tx, int64_t ty) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(tx)) << 32) |
         static_cast<uint64_t>(static_cast<uint32_t>(ty));
}

const OccupancyGrid::Tile* OccupancyGrid::find_tile(int64_t tx, int64_t ty) const {
  const uint64_t key = tile_key(tx, ty);
  if (cached_tile_ && key == cached_key_) return cached_tile_;
  auto it = tiles_.find(key);
  if (it == tiles_.end()) return nullptr;  // absent tiles are not cached: they may appear later
  cached_key_ = key;
  cached_tile_ = it->second.get();
  return cached_tile_;
}

OccupancyGrid::Tile& OccupancyGrid::tile_at(int64_t tx, int64_t ty) {
  const uint64_t key = tile_key(tx, ty);
  if (cached_tile_ && key == cached_key_) return *cached_tile_;
  auto& slot = tiles_[key];
  if (journal_open_ && !journal_.contains(key)) {
    journal_.emplace(key, slot ? std::make_unique<Tile>(*slot) : nullptr);
    if (slot) ++journal_saved_;
  }
  if (!slot) {
    slot = std::make_unique<Tile>();
    if (subcell_) slot->subcell.resize(kTileCells);
  }
  cached_key_ = key;
  cached_tile_ = slot.get();
  return *slot;
}

double OccupancyGrid::cell_probability(int64_t ix, int64_t iy) const {
  const Tile* t = find_tile(floor_div_tile(ix), floor_div_tile(iy));
  if (!t) return 0.5;
  return probability_of_[t->log_odds[in_tile(iy) * kTileSize + in_tile(ix)] + 128];
}

OccupancyGrid::Corner OccupancyGrid::corner(const Eigen::Vector2d& p_map) const {
  const double gx = p_map.x() / resolution_m_, gy = p_map.y() / resolution_m_;
  const double fx0 = std::floor(gx), fy0 = std::floor(gy);
  return {static_cast<int64_t>(fx0), static_cast<int64_t>(fy0), gx - fx0, gy - fy0};
}

double OccupancyGrid::value(const Eigen::Vector2d& p_map, Eigen::Vector2d* gradient,
                            bool at_hits) const {
  if (!subcell_ || !at_hits) return interpolate(p_map, gradient);
  return interpolate(p_map - hit_offset(p_map), gradient);
}

Eigen::Vector2d OccupancyGrid::hit_offset(const Eigen::Vector2d& p_map) const {
  if (!subcell_) return Eigen::Vector2d::Zero();
  const auto [x0, y0, fx, fy] = corner(p_map);
  // Each of the four cells weighs by its bilinear weight times its occupied evidence (probability
  // above 0.5): free and unknown cells say nothing about where a wall lies.
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double weight = 0.0;
  const bool one_tile = in_one_tile(x0, y0);  // the usual case: one look-up
  const Tile* tile = one_tile ? find_tile(floor_div_tile(x0), floor_div_tile(y0)) : nullptr;
  if (one_tile && !tile) return Eigen::Vector2d::Zero();
  for (int dy = 0; dy <= 1; ++dy) {
    for (int dx = 0; dx <= 1; ++dx) {
      const int64_t ix = x0 + dx, iy = y0 + dy;
      const Tile* t = one_tile ? tile : find_tile(floor_div_tile(ix), floor_div_tile(iy));
      if (!t) continue;
      const int64_t i = in_tile(iy) * kTileSize + in_tile(ix);
      const double evidence = probability_of_[t->log_odds[i] + 128] - 0.5;
      if (evidence <= 0.0 || t->subcell[i].count == 0) continue;
      const double w = (dx ? fx : 1.0 - fx) * (dy ? fy : 1.0 - fy) * evidence;
      weight += w;
      sum += w * Eigen::Vector2d(t->subcell[i].x, t->subcell[i].y);
    }
  }
  if (weight <= 0.0) return Eigen::Vector2d::Zero();
  return sum * (resolution_m_ / kOffsetSteps / weight);  // offset steps -> m
}

void OccupancyGrid::add_hit_offset(SubcellHits& h, const Eigen::Vector2d& cell_offset) {
  constexpr int kMaxCount = 32;  // the mean of about the last 32 hits
  const int n = std::min<int>(h.count, kMaxCount - 1) + 1;
  auto mean = [n](int16_t old, double offset_cells) {
    const double x = old + (offset_cells * kOffsetSteps - old) / n;
    return static_cast<int16_t>(std::clamp<long>(std::lround(x), -32767, 32767));
  };
  h.x = mean(h.x, cell_offset.x());
  h.y = mean(h.y, cell_offset.y());
  h.count = static_cast<uint8_t>(n);
}

double OccupancyGrid::interpolate(const Eigen::Vector2d& p_map, Eigen::Vector2d* gradient) const {
  const auto [x0, y0, fx, fy] = corner(p_map);
  double m00, m10, m01, m11;
  if (in_one_tile(x0, y0)) {  // all four cells in one tile: one look-up
    const Tile* t = find_tile(floor_div_tile(x0), floor_div_tile(y0));
    if (!t) {
      if (gradient) gradient->setZero();
      return 0.5;
    }
    const int8_t* c = &t->log_odds[in_tile(y0) * kTileSize + in_tile(x0)];
    m00 = probability_of_[c[0] + 128];
    m10 = probability_of_[c[1] + 128];
    m01 = probability_of_[c[kTileSize] + 128];
    m11 = probability_of_[c[kTileSize + 1] + 128];
  } else {
    m00 = cell_probability(x0, y0);
    m10 = cell_probability(x0 + 1, y0);
    m01 = cell_probability(x0, y0 + 1);
    m11 = cell_probability(x0 + 1, y0 + 1);
  }
  // Eq. 4: interpolate along x on both rows, then along y.
  const double bottom = (1.0 - fx) * m00 + fx * m10;
  const double top = (1.0 - fx) * m01 + fx * m11;
  if (gradient) {
    // Eq. 5-6, divided by the cell size to give the gradient per metre.
    gradient->x() = ((1.0 - fy) * (m10 - m00) + fy * (m11 - m01)) / resolution_m_;
    gradient->y() = (top - bottom) / resolution_m_;
  }
  return (1.0 - fy) * bottom + fy * top;
}

OccupancyGrid::SubcellHits* OccupancyGrid::touch(int64_t ix, int64_t iy, int delta) {
  Tile& t = tile_at(floor_div_tile(ix), floor_div_tile(iy));
  const int64_t i = in_tile(iy) * kTileSize + in_tile(ix);
  SubcellHits* hits = subcell_ ? &t.subcell[i] : nullptr;
  if (t.stamp[i] == stamp_) return hits;
  t.stamp[i] = stamp_;
  t.log_odds[i] = static_cast<int8_t>(std::clamp(t.log_odds[i] + delta, -kLogOddsMax, kLogOddsMax));
  return hits;
}

void OccupancyGrid::trace_free(int64_t x0, int64_t y0, int64_t x1, int64_t y1) {
  // Bresenham from the origin cell up to, not including, the end point's cell.
  const int64_t dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int64_t sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
  int64_t err = dx + dy;
  while (x0 != x1 || y0 != y1) {
    touch(x0, y0, free_delta_);
    const int64_t e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x0 += sx;
    }
    if (e2 <= dx) {
      err += dx;
      y0 += sy;
    }
  }
}

void OccupancyGrid::update(const Eigen::Vector2d& origin_map,
                           const std::vector<Eigen::Vector2d>& hits_map,
                           const std::vector<double>* incidence_sin) {
  if (journal_open_) {  // a tile cached by a read since the journal opened was not saved
    cached_key_ = ~0ULL;
    cached_tile_ = nullptr;
  }
  if (++stamp_ == 0) {  // stamps wrapped: forget old ones so no cell looks already touched
    for (auto& [key, tile] : tiles_) tile->stamp.fill(0);
    stamp_ = 1;
  }
  auto cell = [this](const Eigen::Vector2d& p) {
    return std::pair<int64_t, int64_t>{std::llround(p.x() / resolution_m_),
                                       std::llround(p.y() / resolution_m_)};
  };
  // Hits first, so that the traversals below skip the cells this scan saw occupied.
  for (const auto& p : hits_map) {
    const auto [ix, iy] = cell(p);
    if (SubcellHits* hits = touch(ix, iy, occupied_delta_)) {
      add_hit_offset(*hits, p / resolution_m_ - Eigen::Vector2d(ix, iy));
    }
  }
  // Free space along each beam up to a cell short of the hit, further short when it grazes.
  // Consecutive beams of a dense scan often stop in the same cell: their rays are traced once.
  constexpr double kMinIncidenceSin = 0.05;
  const auto [ox, oy] = cell(origin_map);
  std::pair<int64_t, int64_t> previous{ox, oy};
  for (std::size_t i = 0; i < hits_map.size(); ++i) {
    const Eigen::Vector2d ray = hits_map[i] - origin_map;
    const double range = ray.norm();
    double stop = resolution_m_;
    if (incidence_sin) stop /= std::max(kMinIncidenceSin, (*incidence_sin)[i]);
    if (range <= stop) continue;
    const auto c = cell(hits_map[i] - ray * (stop / range));
    if (c == previous) continue;
    previous = c;
    trace_free(ox, oy, c.first, c.second);
  }
}

Eigen::Vector2d OccupancyGrid::min_corner() const {
  if (tiles_.empty()) return Eigen::Vector2d::Zero();
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300);
  for (const auto& [key, tile] : tiles_) {
    const auto tx = static_cast<int32_t>(key >> 32), ty = static_cast<int32_t>(key & 0xffffffffu);
    lo = lo.cwiseMin(Eigen::Vector2d(tx, ty) * kTileSize * resolution_m_);
  }
  return lo;
}

Eigen::Vector2d OccupancyGrid::max_corner() const {
  if (tiles_.empty()) return Eigen::Vector2d::Zero();
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(-1e300);
  for (const auto& [key, tile] : tiles_) {
    const auto tx = static_cast<int32_t>(key >> 32), ty = static_cast<int32_t>(key & 0xffffffffu);
    hi = hi.cwiseMax(Eigen::Vector2d(tx + 1, ty + 1) * kTileSize * resolution_m_);
  }
  return hi;
}

void OccupancyGrid::begin_journal() {
  end_journal();  // also drops the cached tile: the next touch must look it up (and save it)
  journal_open_ = true;
}

void OccupancyGrid::rollback() {
  for (auto& [key, saved] : journal_) {
    if (saved) {
      tiles_[key] = std::move(saved);
    } else {
      tiles_.erase(key);
    }
  }
  end_journal();
}

void OccupancyGrid::end_journal() {
  journal_.clear();
  journal_saved_ = 0;
  journal_open_ = false;
  cached_key_ = ~0ULL;
  cached_tile_ = nullptr;
}

std::size_t OccupancyGrid::evict_farthest(const Eigen::Vector2d& p_map, std::size_t max_bytes) {
  if (memory_bytes() <= max_bytes) return 0;
  const double tile_m = kTileSize * resolution_m_;
  std::vector<std::pair<double, uint64_t>> by_distance;
  by_distance.reserve(tiles_.size());
  for (const auto& [key, tile] : tiles_) {
    const auto tx = static_cast<int32_t>(key >> 32), ty = static_cast<int32_t>(key & 0xffffffffu);
    const Eigen::Vector2d centre = (Eigen::Vector2d(tx, ty).array() + 0.5).matrix() * tile_m;
    by_distance.emplace_back((centre - p_map).squaredNorm(), key);
  }
  std::sort(by_distance.begin(), by_distance.end(), std::greater<>());
  std::size_t dropped = 0;
  for (const auto& [d2, key] : by_distance) {
    if (memory_bytes() <= max_bytes) break;
    tiles_.erase(key);
    ++dropped;
  }
  cached_key_ = ~0ULL;
  cached_tile_ = nullptr;
  return dropped;
}

}  // namespace traverse::frontend
