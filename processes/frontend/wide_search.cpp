#include "wide_search.hpp"

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
// A step off its arc (sideways or backwards) by StepPrior::off_arc_free_m plus this loses
// StepPrior::off_arc_weight per point, quadratically.
constexpr double kOffArcScaleM = 0.3;

// Tangent of half a step's turn: a chord of an arc turning by `turn` points half as far round
// (sideways = forward * tan).
double tan_half_turn(double turn) {
  return std::tan(std::clamp(0.5 * turn, -M_PI / 4.0, M_PI / 4.0));
}

// StepPrior's cost per point of a step of `length` [m], `forward` [m] along the last heading,
// `side` [m] off the arc through its `turn` [rad] (0 on it).
double step_shape_cost(const StepPrior& sp, double length, double forward, double side,
                       double turn) {
  double cost = 0.0;
  const double inside = 1.0 - std::max(length / sp.min_travel_m, std::abs(turn) / sp.min_turn_rad);
  if (inside > 0.0) cost += sp.short_weight * inside * inside;
  const double e_side = std::max(0.0, side - sp.off_arc_free_m) / kOffArcScaleM;
  const double e_back = std::max(0.0, -forward - sp.off_arc_free_m) / kOffArcScaleM;
  return cost + sp.off_arc_weight * (e_side * e_side + e_back * e_back);
}
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

double step_prior_cost(const StepPrior& sp, const Pose2& T_map_base) {
  if (!(sp.min_travel_m > 0.0 && sp.min_turn_rad > 0.0)) return 0.0;
  const Pose2 step = between(sp.T_last, T_map_base);
  const Eigen::Vector2d v = step.translation();
  return step_shape_cost(sp, v.norm(), v.x(), std::abs(v.y() - v.x() * tan_half_turn(step.theta())),
                         step.theta());
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
  const int64_t cx = std::llround(T_center.x() / res), cy = std::llround(T_center.y() / res);
  const int half = static_cast<int>(std::ceil(r_max / res)) + n_shift + kBlock + 2;
  const int side = 2 * half + 1;
  const auto at = [side](int i, int j) { return static_cast<std::size_t>(j) * side + i; };
  std::vector<float> evidence(static_cast<std::size_t>(side) * side);
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const double p = grid.cell_probability(cx - half + i, cy - half + j);
      evidence[at(i, j)] = cell_evidence(p);
    }
  }
  std::vector<float> table(evidence.size(), 0.0f);
  for (int j = 1; j + 1 < side; ++j) {
    for (int i = 1; i + 1 < side; ++i) {
      table[at(i, j)] =
          blurred_evidence([&](int di, int dj) { return evidence[at(i + di, j + dj)]; });
    }
  }
  // bound(i, j) = max of table over [i, i + kBlock) x [j, j + kBlock), separably.
  std::vector<float> rows(table.size(), 0.0f), bound(table.size(), 0.0f);
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i + kBlock <= side; ++i) {
      float m = -1.0f;
      for (int b = 0; b < kBlock; ++b) m = std::max(m, table[at(i + b, j)]);
      rows[at(i, j)] = m;
    }
  }
  for (int j = 0; j + kBlock <= side; ++j) {
    for (int i = 0; i < side; ++i) {
      float m = -1.0f;
      for (int b = 0; b < kBlock; ++b) m = std::max(m, rows[at(i, j + b)]);
      bound[at(i, j)] = m;
    }
  }

  // Cells of the points rotated by each angle, at the centre's translation.
  const int n_points = static_cast<int>(points_base.size());
  const int n_a = 2 * n_angles + 1;
  std::vector<std::pair<int, int>> cells(static_cast<std::size_t>(n_a) * n_points);
  for (int a = 0; a < n_a; ++a) {
    const Pose2 T(T_center.x(), T_center.y(), T_center.theta() + (a - n_angles) * angle_step);
    for (int k = 0; k < n_points; ++k) {
      const Eigen::Vector2d q = T * points_base[k];
      cells[static_cast<std::size_t>(a) * n_points + k] = {
          static_cast<int>(std::llround(q.x() / res) - cx) + half,
          static_cast<int>(std::llround(q.y() / res) - cy) + half};
    }
  }
  const auto score_of = [&](const std::vector<float>& t, int a, int dx, int dy) {
    float s = 0.0f;
    const auto* c = &cells[static_cast<std::size_t>(a) * n_points];
    for (int k = 0; k < n_points; ++k) s += t[at(c[k].first + dx, c[k].second + dy)];
    return s;
  };

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
  const bool use_step =
      step_prior != nullptr && step_prior->min_travel_m > 0.0 && step_prior->min_turn_rad > 0.0;
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

  // Level 1: every angle and every block of translations, scored by its bound.
  struct Candidate {
    float bound;
    int a, dx, dy;  // angle index, lowest translation of the block [cells]
  };
  std::vector<Candidate> candidates;
  for (int a = 0; a < n_a; ++a) {
    for (int dy = -n_shift; dy <= n_shift; dy += kBlock) {
      for (int dx = -n_shift; dx <= n_shift; dx += kBlock) {
        candidates.push_back({score_of(bound, a, dx, dy) - penalty(a, dx, dy, kBlock), a, dx, dy});
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& l, const Candidate& r) { return l.bound > r.bound; });
  // Level 0: blocks in order of their bound, until no block can hold a pose within `margin` of
  // the best pose found (those poses make the score surface's spread, below).
  const float margin = static_cast<float>(kSurfaceMargin * temperature);
  float best = -std::numeric_limits<float>::infinity();
  int best_a = n_angles, best_dx = 0, best_dy = 0;
  struct Scored {
    float s;
    int a, dx, dy;
  };
  std::vector<Scored> near_best;
  std::size_t kept = 0;
  for (const Candidate& c : candidates) {
    if (c.bound <= best - margin) break;
    for (int dy = c.dy; dy < c.dy + kBlock && dy <= n_shift; ++dy) {
      for (int dx = c.dx; dx < c.dx + kBlock && dx <= n_shift; ++dx) {
        const float s = score_of(table, c.a, dx, dy) - penalty(c.a, dx, dy, 1);
        ++result.evaluated;
        if (temperature > 0.0 && s > best - margin) near_best.push_back({s, c.a, dx, dy});
        if (near_best.size() > 2 * kept + 4096) {  // drop those the best has left behind
          std::erase_if(near_best, [&](const Scored& p) { return p.s <= best - margin; });
          kept = near_best.size();
        }
        if (s > best) {
          best = s;
          best_a = c.a;
          best_dx = dx;
          best_dy = dy;
        }
      }
    }
  }
  result.T_map_base = Pose2(T_center.x() + best_dx * res, T_center.y() + best_dy * res,
                            T_center.theta() + (best_a - n_angles) * angle_step);
  result.score = score_of(table, best_a, best_dx, best_dy) / n_points;

  // Spread of the pose over the score surface: every pose within the margin of the best,
  // weighted by exp((score - best) / temperature), offsets from the best in m and rad. Taken
  // about the best pose (the one reported), not about the weighted mean: a second mode as good
  // is a second place the pose may be.
  if (temperature > 0.0) {
    double w_sum = 0.0;
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    for (const Scored& p : near_best) {
      if (p.s <= best - margin) continue;
      const double w = std::exp((p.s - best) / temperature);
      const Eigen::Vector3d d((p.dx - best_dx) * res, (p.dy - best_dy) * res,
                              wrap_angle((p.a - best_a) * angle_step));
      w_sum += w;
      second += w * d * d.transpose();
      ++result.poses_in_spread;
    }
    result.covariance = second / w_sum;
  }
  return result;
}

}  // namespace traverse::frontend
