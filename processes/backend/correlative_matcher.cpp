#include "correlative_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "config.hpp"
#include "correlative_search.hpp"

namespace traverse::backend {
namespace {

// The lookup table of section III-B over the cells [i0, i0 + width) x [j0, j0 + height) of a grid
// with its origin at `origin`: cell (i, j) covers [origin + i res, origin + (i + 1) res) (and
// likewise in y) and holds exp(-d^2 / 2 sigma^2) of the nearest reference point. Only the cells
// a query can reach are held: a table over the reference points' whole extent spent most of a
// link's time (its block bounds) on cells no query point lands in.
class LookupTable {
 public:
  LookupTable(const std::vector<Eigen::Vector2d>& points, double resolution, double sigma,
              const Eigen::Vector2d& origin, int i0, int j0, int width, int height)
      : resolution_(resolution), origin_(origin), i0_(i0), j0_(j0), scores_(width, height) {
    const int radius = static_cast<int>(std::ceil(3.0 * sigma / resolution));
    stamp_all(points, radius, sigma);
  }

  // The cell of a point, as indices into scores().
  std::pair<int, int> index(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d c = (p - origin_) / resolution_;
    return {static_cast<int>(std::floor(c.x())) - i0_, static_cast<int>(std::floor(c.y())) - j0_};
  }
  const correlative::ScoreTable& scores() const { return scores_; }

 private:
  // The kernel is evaluated once per table on cell offsets; a point is snapped to its cell (the
  // cell is a fraction of the kernel width).
  void stamp_all(const std::vector<Eigen::Vector2d>& points, int radius, double sigma) {
    const int side = 2 * radius + 1;
    std::vector<float> kernel(static_cast<std::size_t>(side) * side);
    for (int dy = -radius; dy <= radius; ++dy) {
      for (int dx = -radius; dx <= radius; ++dx) {
        const double d2 = resolution_ * resolution_ * (dx * dx + dy * dy);
        kernel[(dy + radius) * side + dx + radius] =
            static_cast<float>(std::exp(-0.5 * d2 / (sigma * sigma)));
      }
    }
    for (const auto& p : points) {
      const auto [cx, cy] = index(p);
      if (cx < -radius || cy < -radius || cx > scores_.width() + radius ||
          cy > scores_.height() + radius) {
        continue;
      }
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          if (!scores_.inside(cx + dx, cy + dy)) continue;
          float& v = scores_.at(cx + dx, cy + dy);
          v = std::max(v, kernel[(dy + radius) * side + dx + radius]);
        }
      }
    }
  }

  double resolution_;
  Eigen::Vector2d origin_;
  int i0_, j0_;
  correlative::ScoreTable scores_;
};

// [cells] the largest lookup table built (4 bytes a cell, twice with the block bounds): 256 MB.
constexpr double kMaxTableCells = 32.0 * 1024 * 1024;

}  // namespace

std::optional<std::string> validate(const CorrelativeMatcherConfig& c) {
  ConfigCheck check;
  check.in_range("resolution_m", c.resolution_m, 0.001, 1.0);
  check.in_range("coarse_factor", c.coarse_factor, 1, 64);
  check.positive("angle_step_rad", c.angle_step_rad);
  check.not_negative("linear_window_m", c.linear_window_m);
  check.in_range("angular_window_rad", c.angular_window_rad, 0.0, M_PI);
  check.positive("kernel_sigma_m", c.kernel_sigma_m);
  check.positive("penalty_sigma_xy_m", c.penalty_sigma_xy_m);
  check.positive("penalty_sigma_theta_rad", c.penalty_sigma_theta_rad);
  check.not_negative("covariance_response_drop", c.covariance_response_drop);
  check.in_range("covariance_window_cells", c.covariance_window_cells, 1, 100);
  check.in_range("max_query_points", c.max_query_points, 1, 100000);
  if (check.problem()) return check.problem();
  // The search volume: translations (2 W + 1)^2 per heading, 2 A + 1 headings, and the table's
  // kernel; more than these take seconds per match.
  check.require(c.linear_window_m / c.resolution_m <= 1000.0, "linear_window_m",
                "must be at most 1000 cells of resolution_m");
  check.require(c.angular_window_rad / c.angle_step_rad <= 1000.0, "angular_window_rad",
                "must be at most 1000 angle steps");
  check.require(c.kernel_sigma_m / c.resolution_m <= 100.0, "kernel_sigma_m",
                "must be at most 100 cells of resolution_m");
  return check.problem();
}

CorrelativeMatcher::CorrelativeMatcher(CorrelativeMatcherConfig config)
    : config_(std::move(config)) {}

MatchResult CorrelativeMatcher::match(const std::vector<Eigen::Vector2d>& reference_all,
                                      const std::vector<Eigen::Vector2d>& query_all,
                                      const Pose2& T_world_guess, double second_peak_exclusion_m,
                                      double second_peak_min_share) const {
  MatchResult result;
  if (reference_all.empty() || query_all.empty()) return result;
  if (!Eigen::Vector3d(T_world_guess.x(), T_world_guess.y(), T_world_guess.theta()).allFinite()) {
    return result;
  }
  const CorrelativeMatcherConfig& c = config_;
  const double res = c.resolution_m, step = c.angle_step_rad;
  const int W = static_cast<int>(std::ceil(c.linear_window_m / res));
  const int A = static_cast<int>(std::ceil(c.angular_window_rad / step));

  // Query points thinned evenly (non-finite ones left out), and how far they reach from the
  // query's origin.
  const std::size_t stride = (query_all.size() + c.max_query_points - 1) / c.max_query_points;
  std::vector<Eigen::Vector2d> query;
  double reach = 0.0;
  for (std::size_t i = 0; i < query_all.size(); i += stride) {
    if (!query_all[i].allFinite()) continue;
    query.push_back(query_all[i]);
    reach = std::max(reach, query_all[i].norm());
  }
  if (query.empty()) return result;
  const double n = static_cast<double>(query.size());
  // The table only needs the reference points a query point can land near at some pose of the
  // search window: within its reach plus the window's corner and the kernel's margin of the
  // guess. A larger table than kMaxTableCells (points scattered by a wrong pose, garbage
  // extents) is no match rather than an allocation without bound.
  const double margin = 3.0 * c.kernel_sigma_m;
  reach += std::sqrt(2.0) * (W + c.coarse_factor) * res + 2.0 * margin;
  if (std::pow(2.0 * reach / res, 2) > kMaxTableCells) return result;
  std::vector<Eigen::Vector2d> reference_world;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  for (const Eigen::Vector2d& p : reference_all) {
    if (p.allFinite() && (p - T_world_guess.translation()).cwiseAbs().maxCoeff() <= reach) {
      reference_world.push_back(p);
      lo = lo.cwiseMin(p);
    }
  }
  if (reference_world.empty()) return result;
  // The grid's origin as a table over all these points would have it, so that the scores do not
  // depend on how much of it is held; then the cells any query point reaches at some pose of the
  // search window (its own arc over the headings, the translations and the coarse blocks beyond
  // them, a cell of rounding), with the kernel's margin.
  const Eigen::Vector2d origin = lo - Eigen::Vector2d::Constant(margin);
  Eigen::Vector2d box_lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d box_hi = -box_lo;
  const double turn = A * step, shift = (W + c.coarse_factor + 1) * res + margin;
  for (const Eigen::Vector2d& q : query) {
    const Eigen::Vector2d p = T_world_guess * q;
    const double e = q.norm() * turn + shift;
    box_lo = box_lo.cwiseMin(p - Eigen::Vector2d::Constant(e));
    box_hi = box_hi.cwiseMax(p + Eigen::Vector2d::Constant(e));
  }
  const auto cell = [&](double v, double o) { return static_cast<int>(std::floor((v - o) / res)); };
  const int i0 = std::max(0, cell(box_lo.x(), origin.x()));
  const int j0 = std::max(0, cell(box_lo.y(), origin.y()));
  const int i1 = cell(box_hi.x(), origin.x()), j1 = cell(box_hi.y(), origin.y());
  if (i1 < i0 || j1 < j0) return result;
  const LookupTable table(reference_world, res, c.kernel_sigma_m, origin, i0, j0, i1 - i0 + 1,
                          j1 - j0 + 1);
  const correlative::BlockBound coarse(table.scores(), c.coarse_factor);
  const correlative::RotatedScans scans(query, T_world_guess, A, step,
                                        [&](const Eigen::Vector2d& p) { return table.index(p); });

  // The penalty for straying from the guess, at its least over the translations [i, i + size) x
  // [j, j + size) (the one nearest the guess) of heading a; the response is the mean table value.
  const auto penalty = [&](double di2_cells, int a) {
    const double dth = (a - A) * step;
    return std::exp(-0.5 * (di2_cells * res * res / (c.penalty_sigma_xy_m * c.penalty_sigma_xy_m) +
                            dth * dth / (c.penalty_sigma_theta_rad * c.penalty_sigma_theta_rad)));
  };
  const auto closest = [](int lo, int hi) { return lo > 0 ? lo : (hi < 0 ? -hi : 0); };
  const auto penalised = [&](double sum, int a, int i, int j, int size) {
    const int ci = closest(i, std::min(i + size - 1, W));
    const int cj = closest(j, std::min(j + size - 1, W));
    return sum / n * penalty(ci * ci + cj * cj, a);
  };
  const auto no_visit = [](const correlative::ScoredPose<double>&, double) {};

  // Multi-resolution search (section IV), best-first until no block can beat the best.
  const auto search = correlative::branch_and_bound<double>(
      scans, table.scores(), coarse, W, {-1.0, A, 0, 0}, 0.0, penalised, no_visit);
  result.evaluations = static_cast<long>(search.blocks + search.scored);
  const double best = search.best.score;
  const int best_a = search.best.a, best_i = search.best.dx, best_j = search.best.dy;
  result.valid = true;
  result.response = best;
  result.raw_response = scans.sum<double>(table.scores(), best_a, best_i, best_j) / n;
  // Sub-step refinement: the vertex of a parabola through the best pose and its two neighbours,
  // per axis (the table is smooth at the kernel scale, so the peak is locally quadratic).
  const auto score = [&](int a, int i, int j) {
    if (a < 0 || a > 2 * A || std::abs(i) > W || std::abs(j) > W) return -1.0;
    return penalised(scans.sum<double>(table.scores(), a, i, j), a, i, j, 1);
  };
  const auto vertex = [&](double minus, double plus) {
    const double curvature = minus - 2.0 * best + plus;
    if (minus < 0.0 || plus < 0.0 || curvature >= 0.0) return 0.0;
    return std::clamp(0.5 * (minus - plus) / curvature, -0.5, 0.5);
  };
  const double di = vertex(score(best_a, best_i - 1, best_j), score(best_a, best_i + 1, best_j));
  const double dj = vertex(score(best_a, best_i, best_j - 1), score(best_a, best_i, best_j + 1));
  const double da = vertex(score(best_a - 1, best_i, best_j), score(best_a + 1, best_i, best_j));
  result.evaluations += 6;
  const double theta = T_world_guess.theta() + (best_a + da - A) * step;
  result.T_world_query = Pose2(T_world_guess.x() + (best_i + di) * res,
                               T_world_guess.y() + (best_j + dj) * res, theta);

  // Second peak: the same search on raw responses, poses near the best translation left out.
  if (second_peak_exclusion_m > 0.0) {
    const double excl2 = std::pow(second_peak_exclusion_m / res, 2);
    const auto far_raw = [&](double sum, int a, int i, int j, int size) {
      (void)a;
      if (size == 1 && (i - best_i) * (i - best_i) + (j - best_j) * (j - best_j) < excl2) {
        return -std::numeric_limits<double>::infinity();
      }
      return sum / n;
    };
    const double floor = second_peak_min_share * result.raw_response;
    const auto second = correlative::branch_and_bound<double>(
        scans, table.scores(), coarse, W, {floor, A, 0, 0}, 0.0, far_raw, no_visit);
    result.evaluations += static_cast<long>(second.scored);
    result.second_peak_response = second.best.score > floor ? second.best.score : 0.0;
  }

  // Covariance from the spread of the response around the best pose (section III-D).
  const int cw = c.covariance_window_cells;
  correlative::ScoreSpread spread;
  for (int a = std::max(0, best_a - cw); a <= std::min(2 * A, best_a + cw); ++a) {
    for (int i = std::max(-W, best_i - cw); i <= std::min(W, best_i + cw); ++i) {
      for (int j = std::max(-W, best_j - cw); j <= std::min(W, best_j + cw); ++j) {
        ++result.evaluations;
        const double s = penalised(scans.sum<double>(table.scores(), a, i, j), a, i, j, 1);
        if (s < best - c.covariance_response_drop) continue;
        spread.add(s, Eigen::Vector3d((i - best_i) * res, (j - best_j) * res, (a - best_a) * step));
      }
    }
  }
  if (spread.weight() > 0.0) {
    result.covariance = spread.about_mean();
  } else {  // nothing overlaps anywhere: the whole window is equally likely
    result.covariance =
        Eigen::Vector3d(W * W * res * res, W * W * res * res, A * A * step * step).asDiagonal();
  }
  // The discrete steps bound what the search can resolve: at least a quarter step squared.
  result.covariance(0, 0) += 0.25 * res * res;
  result.covariance(1, 1) += 0.25 * res * res;
  result.covariance(2, 2) += 0.25 * step * step;
  return result;
}

}  // namespace traverse::backend
