#include "scan_matcher.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace traverse::frontend {

MapPyramid::MapPyramid(const MapConfig& config) {
  for (int k = 0; k < std::max(1, config.levels); ++k) {
    grids_.emplace_back(config.resolution_m * std::ldexp(1.0, k), config.p_occupied, config.p_free);
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

NormalEquations normal_equations(const OccupancyGrid& grid,
                                 const std::vector<Eigen::Vector2d>& points_base,
                                 const Pose2& T_map_base) {
  NormalEquations ne;
  const Eigen::Matrix2d R = T_map_base.rotation();
  const double c = R(0, 0), s = R(1, 0);
  Eigen::Vector2d grad;
  for (const auto& p : points_base) {
    const Eigen::Vector2d q = R * p + T_map_base.translation();  // S_i(xi), eq. 7
    const double r = 1.0 - grid.value(q, &grad);
    // dS_i/dpsi (eq. 13) contracted with the map gradient.
    const double dpsi = grad.x() * (-s * p.x() - c * p.y()) + grad.y() * (c * p.x() - s * p.y());
    const Eigen::Vector3d J(grad.x(), grad.y(), dpsi);
    ne.H.noalias() += J * J.transpose();
    ne.g += J * r;
    ne.cost += r * r;
  }
  ne.n = static_cast<int>(points_base.size());
  return ne;
}

namespace {

// Number of distinct cells of `grid` the points fall into (independent observations of the map).
int distinct_cells(const OccupancyGrid& grid, const std::vector<Eigen::Vector2d>& points_base,
                   const Pose2& T_map_base) {
  std::vector<std::pair<int64_t, int64_t>> cells;
  cells.reserve(points_base.size());
  for (const auto& p : points_base) {
    const Eigen::Vector2d q = T_map_base * p;
    cells.emplace_back(std::llround(q.x() / grid.resolution()),
                       std::llround(q.y() / grid.resolution()));
  }
  std::sort(cells.begin(), cells.end());
  return static_cast<int>(std::unique(cells.begin(), cells.end()) - cells.begin());
}

}  // namespace

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
  const int64_t cx = std::llround(T_center.x() / res), cy = std::llround(T_center.y() / res);
  const int half = static_cast<int>(std::ceil(r_max / res)) + n_shift + 1;
  const int side = 2 * half + 1;
  std::vector<float> evidence(static_cast<std::size_t>(side) * side);
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const double p = grid.cell_probability(cx - half + i, cy - half + j);
      evidence[static_cast<std::size_t>(j) * side + i] =
          static_cast<float>(std::max(0.0, 2.0 * (p - 0.5)));
    }
  }
  // Every candidate's score; the winner is the candidate nearest the centre among those within
  // kTolerance of the best score, so that a direction the scan cannot tell apart (a corridor's
  // axis) keeps the centre's value instead of an arbitrary one.
  constexpr double kTolerance = 0.03;
  struct Candidate {
    double score;
    int a, dx, dy;
  };
  std::vector<Candidate> candidates;
  std::vector<std::pair<int, int>> cells(points.size());
  for (int a = -n_angles; a <= n_angles; ++a) {
    const double theta = T_center.theta() + a * angle_step;
    const Pose2 T(T_center.x(), T_center.y(), theta);
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector2d q = T * points[k];
      cells[k] = {static_cast<int>(std::llround(q.x() / res) - cx) + half,
                  static_cast<int>(std::llround(q.y() / res) - cy) + half};
    }
    for (int dy = -n_shift; dy <= n_shift; ++dy) {
      for (int dx = -n_shift; dx <= n_shift; ++dx) {
        double score = 0.0;
        for (const auto& [i, j] : cells)
          score += evidence[static_cast<std::size_t>(j + dy) * side + i + dx];
        candidates.push_back({score, a, dx, dy});
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

namespace {

// Gauss-Newton from T_start over the levels first_level..last_level, with the prior centred on
// T_prior.
MatchResult refine(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                   const Pose2& T_start, const Pose2& T_map_base_predicted,
                   const MatcherConfig& config, int first_level, int last_level) {
  const Eigen::Vector3d prior_information(1.0 / std::pow(config.prior_sigma_xy_m, 2),
                                          1.0 / std::pow(config.prior_sigma_xy_m, 2),
                                          1.0 / std::pow(config.prior_sigma_theta_rad, 2));
  const Eigen::Matrix3d P = prior_information.asDiagonal();
  const Eigen::Vector3d xi_pred = T_map_base_predicted.vector();
  auto prior_error = [&](const Eigen::Vector3d& xi) {
    Eigen::Vector3d e = xi - xi_pred;
    e.z() = wrap_angle(e.z());
    return e;
  };
  const double min_var = config.min_residual_sigma * config.min_residual_sigma;
  const int dof = std::max(1, static_cast<int>(points_base.size()) - 3);

  MatchResult result;
  result.points = static_cast<int>(points_base.size());
  Eigen::Vector3d xi = T_start.vector();
  for (int level = first_level; level >= last_level; --level) {
    const OccupancyGrid& grid = maps.level(level);
    const int iterations = level == 0 ? config.iterations_fine : config.iterations_coarse;
    double previous_cost = std::numeric_limits<double>::infinity();
    Eigen::Vector3d previous_xi = xi, last_step = Eigen::Vector3d::Zero();
    double var = 0.0;  // map-value noise, held fixed on a level so costs stay comparable
    for (int it = 0; it < iterations; ++it) {
      const Pose2 T(xi.x(), xi.y(), xi.z());
      const NormalEquations ne = normal_equations(grid, points_base, T);
      if (it == 0) var = std::max(min_var, ne.cost / dof);
      const Eigen::Vector3d e = prior_error(xi);
      const double cost = ne.cost / var + e.dot(P * e);
      ++result.iterations;
      if (cost > previous_cost) {  // the step overshot: go back half way and try again
        last_step *= 0.5;
        xi = previous_xi + last_step;
        continue;
      }
      previous_cost = cost;
      previous_xi = xi;
      const Eigen::Matrix3d A = ne.H / var + P;
      last_step = A.ldlt().solve(ne.g / var - P * e);
      if (!last_step.allFinite()) break;
      xi += last_step;
      // Converged: the step moves points by well under a hundredth of a cell.
      if (last_step.head<2>().norm() < 1e-2 * grid.resolution() && std::abs(last_step.z()) < 2e-5) {
        break;
      }
    }
  }

  // Covariance at the result on the finest level used (see the header for the scaling).
  const OccupancyGrid& finest = maps.level(last_level);
  const Pose2 T(xi.x(), xi.y(), xi.z());
  const NormalEquations ne = normal_equations(finest, points_base, T);
  const double var = std::max(min_var, ne.cost / dof);
  const int cells = std::max(1, distinct_cells(finest, points_base, T));
  const double points_per_cell = std::max(1.0, static_cast<double>(ne.n) / cells);
  const Eigen::Matrix3d information = ne.H / (var * points_per_cell) + P;
  result.covariance = information.inverse();
  result.covariance = 0.5 * (result.covariance + result.covariance.transpose()).eval();
  result.T_map_base = T;
  result.residual_rms = ne.n > 0 ? std::sqrt(ne.cost / ne.n) : 0.0;
  return result;
}

}  // namespace

bool unverified(const MatchResult& m, const Pose2& T_map_base_predicted,
                const MatcherConfig& config) {
  const Pose2 d = between(T_map_base_predicted, m.T_map_base);
  return m.residual_rms > config.search_trigger_residual &&
         (d.translation().norm() > config.search_max_unverified_m ||
          std::abs(d.theta()) > config.search_max_unverified_rad);
}

MatchResult match_scan(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                       const Pose2& T_map_base_predicted, const MatcherConfig& config,
                       int first_level, int last_level, const std::vector<Pose2>& other_centres) {
  if (first_level < 0 || first_level >= maps.levels()) first_level = maps.levels() - 1;
  last_level = std::clamp(last_level, 0, first_level);
  MatchResult result = refine(maps, points_base, T_map_base_predicted, T_map_base_predicted, config,
                              first_level, last_level);
  if (result.residual_rms <= config.search_trigger_residual) return result;
  std::vector<Pose2> centres{T_map_base_predicted};
  centres.insert(centres.end(), other_centres.begin(), other_centres.end());
  int iterations = result.iterations;
  for (const Pose2& centre : centres) {
    const Pose2 T_start =
        search_pose(maps.level(first_level), points_base, centre, config.search_linear_window_m,
                    config.search_angular_window_rad);
    MatchResult candidate =
        refine(maps, points_base, T_start, centre, config, first_level, last_level);
    iterations += candidate.iterations;
    if (unverified(candidate, T_map_base_predicted, config)) continue;
    if (candidate.residual_rms < result.residual_rms) {
      result = candidate;
      result.searched = true;
    }
  }
  result.iterations = iterations;
  return result;
}

StepPrior step_prior(const MatcherConfig& config, const Pose2& T_last) {
  return {T_last,
          config.sparse_step_min_travel_m,
          config.sparse_step_min_turn_rad,
          config.sparse_step_short_weight,
          config.sparse_step_off_arc_free_m,
          config.sparse_step_off_arc_weight};
}

MatchResult match_scan_wide(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                            const std::vector<Pose2>& priors, const MatcherConfig& config,
                            const Pose2* T_last) {
  const int search_level = std::min(1, maps.levels() - 1);
  const StepPrior prior = T_last ? step_prior(config, *T_last) : StepPrior{};
  const WideSearchResult s =
      wide_search(maps.level(search_level), points_base, priors.front(),
                  config.wide_search_linear_window_m, config.wide_search_angular_window_rad, priors,
                  config.wide_search_temperature, T_last ? &prior : nullptr);
  MatchResult result =
      refine(maps, points_base, s.T_map_base, s.T_map_base, config, maps.levels() - 1, 0);
  // The Gauss-Newton covariance is the curvature where it ended; the search's spread adds what
  // the scan leaves open beyond it (an axis it cannot tell, a second pose that fits as well).
  result.covariance += s.covariance;
  result.searched = true;
  return result;
}

}  // namespace traverse::frontend
