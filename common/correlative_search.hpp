// The parts every correlative scan search of Traverse is made of (Olson, "Real-time correlative
// scan matching", ICRA 2009): the frontend's recovery search and its wide search for sparse scans,
// and the backend's matcher for key-scan links and loop closures. Each search fills a score table
// in its own way and applies its own prior; what a pose scores and how the best is found are here.
//   - ScoreTable: a dense table of scores per cell around the search (section III-B's lookup
//     table); BlockBound: its maxima over blocks of k x k cells, which bound every translation of
//     a block (section IV's low-resolution table).
//   - RotatedScans: the table cells of a scan's points at every heading of the search window, at
//     the window centre's translation: the rotation is applied once per heading, a translation is
//     then an index offset (section IV). sum() adds a table's values under the points.
//   - branch_and_bound(): best-first over blocks of translations per heading, a block expanded
//     pose by pose while its bound can beat the best pose found (section IV). A prior hook turns a
//     summed response into a score (a motion prior, a step prior), taking the prior at its least
//     over a block so that a block's score stays a bound.
//   - ScoreSpread: the second moment of pose offsets weighted by their scores (section III-D): the
//     covariance of what the scores leave open (an axis a corridor cannot tell, a second pose that
//     fits as well).
// Cells are (i, j) integers of the table; headings are indices a = 0 .. 2 * angles, a - angles
// steps of the window's angle step from the centre heading; translations dx, dy are in cells.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "se2.hpp"

namespace traverse::correlative {

// Scores per cell, row-major over 0 <= i < width, 0 <= j < height; a cell outside scores 0.
class ScoreTable {
 public:
  ScoreTable() = default;
  ScoreTable(int width, int height) : width_(width), height_(height), cells_(size(width, height)) {}

  int width() const { return width_; }
  int height() const { return height_; }
  bool inside(int i, int j) const { return i >= 0 && j >= 0 && i < width_ && j < height_; }
  // Cells the caller knows to be inside.
  float& at(int i, int j) { return cells_[index(i, j)]; }
  float at(int i, int j) const { return cells_[index(i, j)]; }
  float operator()(int i, int j) const { return inside(i, j) ? at(i, j) : 0.0f; }
  // The cells, row-major: cell (i, j) at j * width() + i.
  const float* data() const { return cells_.data(); }
  float* data() { return cells_.data(); }

 private:
  static std::size_t size(int width, int height) {
    return static_cast<std::size_t>(std::max(0, width)) *
           static_cast<std::size_t>(std::max(0, height));
  }
  std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(width_) +
           static_cast<std::size_t>(i);
  }

  int width_ = 0, height_ = 0;
  std::vector<float> cells_;
};

// The bound of a block of k x k translations: cell (i, j) holds the largest value of `table` over
// [i, i + k) x [j, j + k) (cut at the table's edges). A block starting up to k - 1 cells left of
// or below the table is bounded by the block starting at the edge (it covers the block's cells in
// the table); a block wholly outside bounds 0.
class BlockBound {
 public:
  BlockBound() = default;
  BlockBound(const ScoreTable& table, int k);

  int block() const { return k_; }
  bool inside(int i, int j) const { return max_.inside(i, j); }
  float at(int i, int j) const { return max_.at(i, j); }
  float operator()(int i, int j) const {
    if (i < 0 && i > -k_) i = 0;
    if (j < 0 && j > -k_) j = 0;
    return max_(i, j);
  }

 private:
  int k_ = 1;
  ScoreTable max_;
};

// The table cells of a scan's points at each heading of a search window (see the header).
class RotatedScans {
 public:
  // points: in the scan's (base) frame; headings T_centre.theta() + (a - angles) * angle_step;
  // cell_of(p_map) -> std::pair<int, int>: the table cell of a point in the map frame.
  template <class CellOf>
  RotatedScans(const std::vector<Eigen::Vector2d>& points, const Pose2& T_centre, int angles,
               double angle_step, CellOf cell_of)
      : angles_(angles), points_(static_cast<int>(points.size())) {
    cells_.resize(static_cast<std::size_t>(headings()) * points.size());
    boxes_.resize(static_cast<std::size_t>(headings()));
    for (int a = 0; a < headings(); ++a) {
      const Pose2 T(T_centre.x(), T_centre.y(), T_centre.theta() + (a - angles) * angle_step);
      Box& box = boxes_[static_cast<std::size_t>(a)];
      for (int k = 0; k < points_; ++k) {
        const std::pair<int, int> c = cell_of(T * points[static_cast<std::size_t>(k)]);
        cells_[static_cast<std::size_t>(a) * points.size() + static_cast<std::size_t>(k)] = c;
        box.add(c.first, c.second);
      }
    }
  }

  int angles() const { return angles_; }
  int headings() const { return 2 * angles_ + 1; }
  int points() const { return points_; }

  // The sum of `table` (ScoreTable or BlockBound) under the points at heading a, shifted by (dx,
  // dy) cells, accumulated in Sum (the result depends on it: float and double round apart).
  template <class Sum, class Table>
  Sum sum(const Table& table, int a, int dx, int dy) const {
    const std::pair<int, int>* c = &cells_[static_cast<std::size_t>(a) * points_];
    const Box& box = boxes_[static_cast<std::size_t>(a)];
    Sum s = 0;
    if (box.empty || (table.inside(box.i_lo + dx, box.j_lo + dy) &&
                      table.inside(box.i_hi + dx, box.j_hi + dy))) {
      for (int k = 0; k < points_; ++k) s += table.at(c[k].first + dx, c[k].second + dy);
    } else {
      for (int k = 0; k < points_; ++k) s += table(c[k].first + dx, c[k].second + dy);
    }
    return s;
  }

 private:
  // The cells' extent at one heading: where every lookup is inside, the table is not checked.
  struct Box {
    bool empty = true;
    int i_lo = 0, i_hi = 0, j_lo = 0, j_hi = 0;
    void add(int i, int j) {
      i_lo = empty ? i : std::min(i_lo, i);
      i_hi = empty ? i : std::max(i_hi, i);
      j_lo = empty ? j : std::min(j_lo, j);
      j_hi = empty ? j : std::max(j_hi, j);
      empty = false;
    }
  };
  int angles_ = 0, points_ = 0;
  std::vector<std::pair<int, int>> cells_;  // heading-major
  std::vector<Box> boxes_;
};

// A pose of the search: heading index a, translation (dx, dy) [cells], and its score.
template <class T>
struct ScoredPose {
  T score;
  int a = 0, dx = 0, dy = 0;
};

template <class T>
struct SearchResult {
  ScoredPose<T> best;
  int64_t blocks = 0;  // blocks bounded (every heading's)
  int64_t scored = 0;  // poses scored exactly (those of the blocks expanded)
};

// Branch and bound over the headings of `scans` and translations dx, dy in [-shifts, shifts]:
// every block of bound.block() x bound.block() translations is bounded by the sum of `bound`
// under its points, blocks are expanded best-first, and each pose of a block is scored by the
// sum of `table` under its points; the search stops at the first block whose bound is at most
// the best score minus `margin` (0: the exact best; a margin > 0 also scores every pose within
// it of the best). prior(sum, a, dx, dy, size) is the score of summed response `sum` at heading
// a for the translations [dx, dx + size) x [dy, dy + size) (at its least over them: a block's
// score must bound its poses'). on_pose(pose, best) sees every pose scored with the best score
// before it. `start`: the best before the search (its score the least that counts). Ties go to
// the pose scored first: headings, then rows dy, then dx, in the order of their block's bound.
template <class T, class Prior, class OnPose>
SearchResult<T> branch_and_bound(const RotatedScans& scans, const ScoreTable& table,
                                 const BlockBound& bound, int shifts, ScoredPose<T> start, T margin,
                                 Prior prior, OnPose on_pose) {
  struct Block {
    T bound;
    int a, dx, dy;  // heading, lowest translation of the block [cells]
  };
  const int k = bound.block();
  std::vector<Block> blocks;
  for (int a = 0; a < scans.headings(); ++a) {
    for (int dy = -shifts; dy <= shifts; dy += k) {
      for (int dx = -shifts; dx <= shifts; dx += k) {
        blocks.push_back({prior(scans.template sum<T>(bound, a, dx, dy), a, dx, dy, k), a, dx, dy});
      }
    }
  }
  std::sort(blocks.begin(), blocks.end(),
            [](const Block& l, const Block& r) { return l.bound > r.bound; });
  SearchResult<T> result{start, static_cast<int64_t>(blocks.size()), 0};
  ScoredPose<T>& best = result.best;
  for (const Block& b : blocks) {
    if (b.bound <= best.score - margin) break;
    for (int dy = b.dy; dy < b.dy + k && dy <= shifts; ++dy) {
      for (int dx = b.dx; dx < b.dx + k && dx <= shifts; ++dx) {
        const ScoredPose<T> pose{prior(scans.template sum<T>(table, b.a, dx, dy), b.a, dx, dy, 1),
                                 b.a, dx, dy};
        ++result.scored;
        on_pose(pose, best.score);
        if (pose.score > best.score) best = pose;
      }
    }
  }
  return result;
}

// The spread of a pose over a score surface (Olson 2009, section III-D): poses' offsets (x [m],
// y [m], theta [rad]) from a chosen pose, weighted (by their score or a function of it).
class ScoreSpread {
 public:
  void add(double weight, const Eigen::Vector3d& offset) {
    weight_ += weight;
    first_ += weight * offset;
    second_ += weight * offset * offset.transpose();
  }
  double weight() const { return weight_; }
  // The second moment about the chosen pose [m^2, m rad, rad^2]: a second mode as good as the
  // chosen pose is a second place it may be. Zero weight: zero.
  Eigen::Matrix3d about_chosen() const {
    return weight_ > 0.0 ? Eigen::Matrix3d(second_ / weight_) : Eigen::Matrix3d::Zero();
  }
  // The covariance about the weighted mean. Zero weight: zero.
  Eigen::Matrix3d about_mean() const {
    if (!(weight_ > 0.0)) return Eigen::Matrix3d::Zero();
    const Eigen::Vector3d mean = first_ / weight_;
    return second_ / weight_ - mean * mean.transpose();
  }

 private:
  double weight_ = 0.0;
  Eigen::Vector3d first_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second_ = Eigen::Matrix3d::Zero();
};

}  // namespace traverse::correlative
