#include "grid_search.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace traverse::frontend {
namespace {
// Weight of the motion prior in the wide search, per point (see wide_search()).
constexpr double kMotionWeight = 0.05;
// Poses scoring more than this many temperatures below the best weigh under exp(-8) = 3e-4 in the
// score surface's spread, and are left out of it.
constexpr double kSurfaceMargin = 8.0;
// Evidence 2 (p - 0.5) of a cell of occupancy probability p.
float cell_evidence(double p) { return static_cast<float>(2.0 * (p - 0.5)); }

// The search's evidence of a cell, blurred: its own, or half that of its most occupied neighbour
// if that is larger (free space is not spread). `at(di, dj)`: the evidence of the cell (di, dj)
// away, di and dj in -1..1.
template <class At>
float blurred_evidence(At at) {
  float m = 0.0f;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) m = std::max(m, at(di, dj));
  return m > 0.0f ? std::max(at(0, 0), 0.5f * m) : at(0, 0);
}

// A search's table of the grid's cells around a centre pose: table cell (i, j) is the grid's
// cell (cx - half + i, cy - half + j), the grid's cell of the centre (cx, cy) in the middle.
class TableWindow {
 public:
  TableWindow(const OccupancyGrid& grid, const Pose2& T_center, int half)
      : grid_(grid),
        res_(grid.resolution()),
        cx_(std::llround(T_center.x() / res_)),
        cy_(std::llround(T_center.y() / res_)),
        half_(half) {}
  int side() const { return 2 * half_ + 1; }
  // The table cell of a point in the map frame.
  std::pair<int, int> operator()(const Eigen::Vector2d& q) const {
    return {static_cast<int>(std::llround(q.x() / res_) - cx_) + half_,
            static_cast<int>(std::llround(q.y() / res_) - cy_) + half_};
  }
  // The table of evidence(p) of the cells, p their occupancy probability (0.5 where unknown).
  template <class Evidence>
  correlative::ScoreTable table(Evidence evidence) const {
    correlative::ScoreTable t(side(), side());
    for (int j = 0; j < side(); ++j) {
      for (int i = 0; i < side(); ++i) {
        t.at(i, j) = evidence(grid_.cell_probability(cx_ - half_ + i, cy_ - half_ + j));
      }
    }
    return t;
  }

 private:
  const OccupancyGrid& grid_;
  double res_;
  int64_t cx_, cy_;
  int half_;
};
}  // namespace

double pose_evidence(const OccupancyGrid& grid, const std::vector<Eigen::Vector2d>& points_base,
                     const Pose2& T_map_base) {
  if (points_base.empty()) return 0.0;
  const double res = grid.resolution();
  double sum = 0.0;
  for (const auto& p : points_base) {
    const Eigen::Vector2d q = T_map_base * p;
    const int64_t i = std::llround(q.x() / res), j = std::llround(q.y() / res);
    sum += blurred_evidence(
        [&](int di, int dj) { return cell_evidence(grid.cell_probability(i + di, j + dj)); });
  }
  return sum / static_cast<double>(points_base.size());
}

Pose2 search_pose(const OccupancyGrid& grid, const std::vector<Eigen::Vector2d>& points_base,
                  const Pose2& T_center, double linear_window_m, double angular_window_rad) {
  constexpr std::size_t kMaxPoints = 200;
  constexpr int kMaxAngles = 181;
  const double res = grid.resolution();
  std::vector<Eigen::Vector2d> points;
  const std::size_t stride = std::max<std::size_t>(1, points_base.size() / kMaxPoints);
  double r_max = res;
  for (std::size_t i = 0; i < points_base.size(); i += stride) {
    points.push_back(points_base[i]);
    r_max = std::max(r_max, points_base[i].norm());
  }
  const double angle_step = std::max(res / r_max, 2.0 * angular_window_rad / (kMaxAngles - 1));
  const int n_angles = static_cast<int>(std::ceil(angular_window_rad / angle_step));
  const int n_shift = static_cast<int>(std::ceil(linear_window_m / res));
  // A dense copy of the grid around the centre: occupied evidence max(0, 2 (p - 0.5)), so that
  // unknown space scores nothing and free space nothing either.
  const TableWindow window(grid, T_center, static_cast<int>(std::ceil(r_max / res)) + n_shift + 1);
  const correlative::ScoreTable evidence =
      window.table([](double p) { return static_cast<float>(std::max(0.0, 2.0 * (p - 0.5))); });
  const correlative::RotatedScans scans(points, T_center, n_angles, angle_step, window);
  // Every candidate's score; the winner is the candidate nearest the centre among those within
  // kTolerance of the best score, so that a direction the scan cannot tell apart (a corridor's
  // axis) keeps the centre's value instead of an arbitrary one.
  constexpr double kTolerance = 0.03;
  struct Candidate {
    double score;
    int a, dx, dy;
  };
  std::vector<Candidate> candidates;
  for (int a = -n_angles; a <= n_angles; ++a) {
    for (int dy = -n_shift; dy <= n_shift; ++dy) {
      for (int dx = -n_shift; dx <= n_shift; ++dx) {
        candidates.push_back({scans.sum<double>(evidence, a + n_angles, dx, dy), a, dx, dy});
      }
    }
  }
  double best_score = 0.0;
  for (const auto& c : candidates) best_score = std::max(best_score, c.score);
  const Candidate* best = nullptr;
  double best_distance = std::numeric_limits<double>::infinity();
  for (const auto& c : candidates) {
    if (c.score < (1.0 - kTolerance) * best_score) continue;
    const double distance = std::hypot(c.dx * res, c.dy * res) / linear_window_m +
                            std::abs(c.a * angle_step) / angular_window_rad;
    if (distance < best_distance) {
      best_distance = distance;
      best = &c;
    }
  }
  if (!best) return T_center;
  return Pose2(T_center.x() + best->dx * res, T_center.y() + best->dy * res,
               T_center.theta() + best->a * angle_step);
}

WideSearchResult wide_search(const OccupancyGrid& grid,
                             const std::vector<Eigen::Vector2d>& points_base, const Pose2& T_center,
                             double linear_window_m, double angular_window_rad,
                             const std::vector<Pose2>& priors, double temperature,
                             const StepPrior* step_prior) {
  // Block side of the coarse level of the branch and bound [cells]: a coarse candidate stands for
  // kBlock x kBlock translations, bounded by the maximum of the table over that block.
  constexpr int kBlock = 4;
  constexpr int kMaxAngles = 721;
  WideSearchResult result;
  result.T_map_base = T_center;
  if (points_base.empty()) return result;
  const double res = grid.resolution();

  // Angle step: the point at the 90th percentile of range moves one cell (the farthest few
  // points would ask for a needlessly fine step).
  std::vector<double> ranges;
  ranges.reserve(points_base.size());
  double r_max = res;
  for (const auto& p : points_base) {
    ranges.push_back(p.norm());
    r_max = std::max(r_max, ranges.back());
  }
  const std::size_t k90 = ranges.size() * 9 / 10;
  std::nth_element(ranges.begin(), ranges.begin() + k90, ranges.end());
  const double r_ref = std::max(ranges[k90], 10.0 * res);
  const double angle_step = std::max(res / r_ref, 2.0 * angular_window_rad / (kMaxAngles - 1));
  const int n_angles = static_cast<int>(std::ceil(angular_window_rad / angle_step));
  const int n_shift = static_cast<int>(std::ceil(linear_window_m / res));

  // Dense table of evidence 2 (p - 0.5) around the centre (occupied up to 1, free down to -1,
  // unknown 0), blurred by taking the larger of a cell's own evidence and half its occupied
  // neighbours'.
  const TableWindow window(grid, T_center,
                           static_cast<int>(std::ceil(r_max / res)) + n_shift + kBlock + 2);
  const int side = window.side();
  const correlative::ScoreTable evidence = window.table(cell_evidence);
  correlative::ScoreTable table(side, side);
  for (int j = 1; j + 1 < side; ++j) {
    for (int i = 1; i + 1 < side; ++i) {
      table.at(i, j) =
          blurred_evidence([&](int di, int dj) { return evidence.at(i + di, j + dj); });
    }
  }
  const correlative::BlockBound bound(table, kBlock);
  const correlative::RotatedScans scans(points_base, T_center, n_angles, angle_step, window);
  const int n_points = scans.points();

  // Motion prior: poses far from every prior pose (the predictions) lose score, so that where the
  // scan cannot tell poses apart (along a corridor) a prediction wins. Per point, so the weight
  // does not depend on the scan's size: w min_h ((d_h / (window / 2))^2 + (dtheta_h /
  // (window / 2))^2). A block of translations is charged its smallest penalty (a valid bound).
  const double w_motion = kMotionWeight;
  const double cells_sigma = 0.5 * linear_window_m / res;
  const double angle_sigma = 0.5 * angular_window_rad;
  struct Offset {
    double x, y, theta;  // [cells], [cells], [rad] from the centre
  };
  std::vector<Offset> offsets;
  for (const Pose2& p : priors) {
    offsets.push_back({(p.x() - T_center.x()) / res, (p.y() - T_center.y()) / res,
                       wrap_angle(p.theta() - T_center.theta())});
  }
  if (offsets.empty()) offsets.push_back({0.0, 0.0, 0.0});
  // Squared distance from h to the interval [lo, lo + size - 1].
  const auto gap_sq = [](int lo, int size, double h) {
    const double d = h < lo ? lo - h : (h > lo + size - 1 ? h - (lo + size - 1) : 0.0);
    return d * d;
  };
  // Step prior (StepPrior): per point, the smallest over a block of translations (a valid bound):
  // the step's length is largest at a corner, and its forward and sideways parts, linear in the
  // translation for one heading, are extreme at corners.
  const bool use_step = step_prior != nullptr && step_prior->active();
  const Eigen::Vector2d last_cells =
      use_step ? Eigen::Vector2d((step_prior->T_last.translation() - T_center.translation()) / res)
               : Eigen::Vector2d::Zero();
  // Per angle: the step's turn and the tangent of half of it (the chord of an arc turning by
  // `turn` points half as far round: sideways = forward * tan).
  std::vector<double> step_turn, step_tan_half;
  const Eigen::Matrix2d R_last_map =
      use_step ? Eigen::Matrix2d(step_prior->T_last.rotation().transpose())
               : Eigen::Matrix2d::Identity();
  if (use_step) {
    for (int a = 0; a < 2 * n_angles + 1; ++a) {
      step_turn.push_back(
          wrap_angle(T_center.theta() + (a - n_angles) * angle_step - step_prior->T_last.theta()));
      step_tan_half.push_back(tan_half_turn(step_turn.back()));
    }
  }
  const auto step_cost = [&](int a, int dx, int dy, int size) {
    if (!use_step) return 0.0;
    const double tan_half = step_tan_half[a];
    double length = 0.0, forward = -std::numeric_limits<double>::infinity();
    double side_lo = std::numeric_limits<double>::infinity(), side_hi = -side_lo;
    for (const int cx : {dx, dx + size - 1}) {
      for (const int cy : {dy, dy + size - 1}) {
        const Eigen::Vector2d v = R_last_map * (res * (Eigen::Vector2d(cx, cy) - last_cells));
        length = std::max(length, v.norm());
        forward = std::max(forward, v.x());
        side_lo = std::min(side_lo, v.y() - v.x() * tan_half);
        side_hi = std::max(side_hi, v.y() - v.x() * tan_half);
      }
    }
    const double side = side_lo > 0.0 ? side_lo : (side_hi < 0.0 ? -side_hi : 0.0);
    return step_shape_cost(*step_prior, length, forward, side, step_turn[a]);
  };
  const auto penalty = [&](int a, int dx, int dy, int size) {
    const double theta = (a - n_angles) * angle_step;
    double best_h = std::numeric_limits<double>::infinity();
    for (const Offset& o : offsets) {
      const double da = (theta - o.theta) / angle_sigma;
      best_h = std::min(
          best_h,
          (gap_sq(dx, size, o.x) + gap_sq(dy, size, o.y)) / (cells_sigma * cells_sigma) + da * da);
    }
    return static_cast<float>(n_points * (w_motion * best_h + step_cost(a, dx, dy, size)));
  };

  // Blocks of translations in order of their bound, until no block can hold a pose within
  // `margin` of the best pose found (those poses make the score surface's spread, below).
  const float margin = static_cast<float>(kSurfaceMargin * temperature);
  struct Scored {
    float s;
    int a, dx, dy;
  };
  std::vector<Scored> near_best;
  std::size_t kept = 0;
  const auto prior = [&](float sum, int a, int dx, int dy, int size) {
    return sum - penalty(a, dx, dy, size);
  };
  const auto keep_near_best = [&](const correlative::ScoredPose<float>& p, float best) {
    if (temperature > 0.0 && p.score > best - margin)
      near_best.push_back({p.score, p.a, p.dx, p.dy});
    if (near_best.size() > 2 * kept + 4096) {  // drop those the best has left behind
      std::erase_if(near_best, [&](const Scored& q) { return q.s <= best - margin; });
      kept = near_best.size();
    }
  };
  const auto search = correlative::branch_and_bound<float>(
      scans, table, bound, n_shift, {-std::numeric_limits<float>::infinity(), n_angles, 0, 0},
      margin, prior, keep_near_best);
  result.evaluated = search.scored;
  const float best = search.best.score;
  const int best_a = search.best.a, best_dx = search.best.dx, best_dy = search.best.dy;
  result.T_map_base = Pose2(T_center.x() + best_dx * res, T_center.y() + best_dy * res,
                            T_center.theta() + (best_a - n_angles) * angle_step);
  result.score = scans.sum<float>(table, best_a, best_dx, best_dy) / n_points;

  // Spread of the pose over the score surface: every pose within the margin of the best,
  // weighted by exp((score - best) / temperature), offsets from the best in m and rad. Taken
  // about the best pose (the one reported), not about the weighted mean: a second mode as good
  // is a second place the pose may be.
  if (temperature > 0.0) {
    correlative::ScoreSpread spread;
    for (const Scored& p : near_best) {
      if (p.s <= best - margin) continue;
      spread.add(std::exp((p.s - best) / temperature),
                 Eigen::Vector3d((p.dx - best_dx) * res, (p.dy - best_dy) * res,
                                 wrap_angle((p.a - best_a) * angle_step)));
      ++result.poses_in_spread;
    }
    result.covariance = spread.about_chosen();
  }
  return result;
}

}  // namespace traverse::frontend
