// One level of the frontend's map: a log-odds occupancy grid stored in square tiles that are
// created on first touch, so the map grows with the area covered and has no edge to run into.
//
// Follows Kohlbrecher et al., "A flexible and scalable SLAM system with full 3D motion
// estimation" (SSRR 2011), section IV.A: the map value M(P) is the occupancy probability of the
// cell, and a continuous value and its gradient come from bilinear interpolation of the four
// surrounding cells (eq. 4-6). Cell (i, j) is sampled at (i * resolution, j * resolution) in the
// map frame. Log-odds are stored as 8-bit integers (1 byte plus 1 byte of update stamp per cell).
//
// Sub-cell hits (not in the paper; `subcell` on): a cell also keeps where in it the scans' end
// points fell (their running mean, 6 bytes more per cell), and M(p) is read at p moved by the
// occupancy-weighted mean of the four surrounding cells' offsets, so the map's ridge lies where
// the walls were seen, not on the cell centres. Without it, a wall a small angle off the grid's
// axes is a staircase of cells (one step every resolution / angle metres: 17 m at 5 cm and
// 3 mrad), and matching a scan of it turns the pose until the wall runs along the axis
// (docs/frontends.md, "The grid's axes pull the walls").
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

namespace traverse::frontend {

class OccupancyGrid {
 public:
  static constexpr int kTileBits = 6;  // 64 x 64 cells per tile
  static constexpr int kTileSize = 1 << kTileBits;
  static constexpr int kTileCells = kTileSize * kTileSize;

  // p_occupied / p_free: probability of occupancy given a hit / a traversal (Hector 0.9 / 0.4).
  // subcell: keep the mean of the hits in each cell and read the map there (above).
  OccupancyGrid(double resolution_m, double p_occupied, double p_free, bool subcell = false);

  double resolution() const { return resolution_m_; }

  // Occupancy probability of one cell; 0.5 where nothing was observed.
  double cell_probability(int64_t ix, int64_t iy) const;

  // M(p) by bilinear interpolation (eq. 4) and, if `gradient` is given, dM/dp [1/m] (eq. 5-6).
  // With sub-cell hits and `at_hits`, M(p - o(p)) with o the hits' offset from the cell centres
  // near p, and as its gradient grad M at p - o(p): the offset held, its own variation left out.
  // That variation is the jumps of the hits' means from one cell to the next (noise of a few
  // millimetres over a 5 cm cell), and carried into Gauss-Newton it makes the steps wander: on the
  // relations benchmark's intel log the frontend slid 2.4 m at 669 s with it, and holds with it
  // left out (docs/frontends.md, "Sub-cell hits"). Without `at_hits` the plain map is read.
  double value(const Eigen::Vector2d& p_map, Eigen::Vector2d* gradient = nullptr,
               bool at_hits = true) const;
  // The offset o(p) of the hits near p from their cells' centres [m] (zero without sub-cell hits
  // or where no cell near p is more likely occupied than not).
  Eigen::Vector2d hit_offset(const Eigen::Vector2d& p_map) const;

  // Integrates one scan seen from `origin_map`: cells on each ray become more likely free, the end
  // point's cell more likely occupied. Each cell is updated at most once per call and a hit wins
  // over a traversal. `incidence_sin` (optional, one per hit) is |sin| of the angle between the
  // beam and the surface it hit: a beam grazing a wall runs within a cell of the wall for
  // resolution / sin metres before its end, so the free-space update stops that far short (else
  // grazing beams of later scans erase the wall cells that earlier scans saw).
  void update(const Eigen::Vector2d& origin_map, const std::vector<Eigen::Vector2d>& hits_map,
              const std::vector<double>* incidence_sin = nullptr);

  // Bytes held by the cells (tiles x tile size, and the tiles an open journal saved); the map's
  // memory use to report.
  std::size_t memory_bytes() const { return (tiles_.size() + journal_saved_) * tile_bytes(); }
  std::size_t tile_count() const { return tiles_.size(); }
  // Extent of the observed area [m]: min and max corner of all tiles, zero if empty.
  Eigen::Vector2d min_corner() const;
  Eigen::Vector2d max_corner() const;

  // Drops the tiles farthest from `p_map` until memory_bytes() <= max_bytes. Returns tiles dropped.
  std::size_t evict_farthest(const Eigen::Vector2d& p_map, std::size_t max_bytes);

  // Journal: while open, update() first saves each tile it changes, so that rollback() can put
  // the grid back exactly as begin_journal() found it (log-odds are clamped: an update cannot
  // be undone by its opposite). end_journal() keeps the changes. Opening a journal ends the last.
  void begin_journal();
  void rollback();
  void end_journal();
  bool journal_open() const { return journal_open_; }

 private:
  // Mean offset of a cell's hits from its centre, x and y in steps of resolution / kOffsetSteps
  // (+-32767: just under half a cell), and how many hits the mean holds (capped, so the mean
  // follows the latest hits).
  struct SubcellHits {
    int16_t x = 0, y = 0;
    uint8_t count = 0;
  };
  struct Tile {
    std::array<int8_t, kTileCells> log_odds{};  // in steps of kLogOddsStep
    std::array<uint8_t, kTileCells> stamp{};    // update() call that last touched the cell
    // Sub-cell hits, one per cell when on (else empty).
    std::vector<SubcellHits> subcell;
  };
  static constexpr double kOffsetSteps = 65535.0;
  std::size_t tile_bytes() const {
    return sizeof(Tile) + (subcell_ ? kTileCells * sizeof(SubcellHits) : 0);
  }
  // The cell (x0, y0) at or below p and p's fractions of a cell beyond it: the four cells
  // (x0..x0+1, y0..y0+1) around p and its bilinear weights.
  struct Corner {
    int64_t x0, y0;
    double fx, fy;
  };
  Corner corner(const Eigen::Vector2d& p_map) const;
  // Bilinear M(p) on the cell centres (eq. 4-6).
  double interpolate(const Eigen::Vector2d& p_map, Eigen::Vector2d* gradient) const;
  // Adds one hit at `cell_offset` (cells, each in [-0.5, 0.5]) to a cell's mean.
  static void add_hit_offset(SubcellHits& hits, const Eigen::Vector2d& cell_offset);
  static uint64_t tile_key(int64_t tx, int64_t ty);
  const Tile* find_tile(int64_t tx, int64_t ty) const;
  Tile& tile_at(int64_t tx, int64_t ty);
  // Applies `delta` to cell (ix, iy) unless this update already touched it; returns the cell's
  // sub-cell record (null without sub-cell hits).
  SubcellHits* touch(int64_t ix, int64_t iy, int delta);
  void trace_free(int64_t x0, int64_t y0, int64_t x1, int64_t y1);

  double resolution_m_;
  bool subcell_;
  int occupied_delta_;
  int free_delta_;
  std::array<float, 256> probability_of_{};  // indexed by log-odds + 128
  std::unordered_map<uint64_t, std::unique_ptr<Tile>> tiles_;
  uint8_t stamp_ = 0;
  // Tiles as they were when the journal opened (null: the tile did not exist).
  bool journal_open_ = false;
  std::unordered_map<uint64_t, std::unique_ptr<Tile>> journal_;
  std::size_t journal_saved_ = 0;  // entries holding a tile
  // One-entry cache of the last tile looked up: consecutive look-ups mostly hit the same tile.
  mutable uint64_t cached_key_ = ~0ULL;
  mutable Tile* cached_tile_ = nullptr;
};

}  // namespace traverse::frontend
