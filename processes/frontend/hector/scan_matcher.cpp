#include "scan_matcher.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "degeneracy.hpp"
#include "grid_search.hpp"
#include "step_prior.hpp"
#include "surface_normals.hpp"

namespace traverse::frontend {

NormalEquations normal_equations(const OccupancyGrid& grid,
                                 const std::vector<Eigen::Vector2d>& points_base,
                                 const Pose2& T_map_base,
                                 const std::vector<Eigen::Vector2d>* normals_base,
                                 bool at_hits) {
  NormalEquations ne;
  const Eigen::Matrix2d R = T_map_base.rotation();
  const double c = R(0, 0), s = R(1, 0);
  Eigen::Vector2d grad;
  for (std::size_t i = 0; i < points_base.size(); ++i) {
    const Eigen::Vector2d& p = points_base[i];
    const Eigen::Vector2d q = R * p + T_map_base.translation();  // S_i(xi), eq. 7
    const double r = 1.0 - grid.value(q, &grad, at_hits);
    if (normals_base && !(*normals_base)[i].isZero()) {
      // Only the gradient across the point's surface (surface_normals.hpp).
      const Eigen::Vector2d n = R * (*normals_base)[i];
      grad = grad.dot(n) * n;
    }
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

namespace {

// Gauss-Newton from T_start over the levels first_level..last_level, with the prior centred on
// T_prior; with normals and MatcherConfig::normal_projection, each point matched across its
// surface only; the normals also give the result's information (degeneracy.hpp).
MatchResult refine(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                   const std::vector<Eigen::Vector2d>* normals, const Pose2& T_start,
                   const Pose2& T_map_base_predicted, const MatcherConfig& config, int first_level,
                   int last_level) {
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
      const NormalEquations ne =
          normal_equations(grid, points_base, T, config.normal_projection ? normals : nullptr,
                           config.read_at_hits);
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

  // Covariance at the result on the finest level used (see the header for the scaling), from the
  // whole map gradient even when the match took only its part across each surface: a normal
  // fitted through noisy points is tilted by a degree or so, and the projected gradient's share
  // along a bare corridor's axis would claim centimetres there that nothing measures. The
  // information degeneracy.hpp weighs is the projected one (whether or not the match used it):
  // there that share is a thousandth of the across-wall one, a clear weak direction, where the
  // whole gradient's pulls along the walls (the map's history) blur it.
  const OccupancyGrid& finest = maps.level(last_level);
  const Pose2 T(xi.x(), xi.y(), xi.z());
  const NormalEquations ne = normal_equations(finest, points_base, T, nullptr, config.read_at_hits);
  const double var = std::max(min_var, ne.cost / dof);
  const int cells = std::max(1, distinct_cells(finest, points_base, T));
  const double points_per_cell = std::max(1.0, static_cast<double>(ne.n) / cells);
  result.covariance = (ne.H / (var * points_per_cell) + P).inverse();
  const Eigen::Matrix3d H_matched =
      normals ? normal_equations(finest, points_base, T, normals, config.read_at_hits).H : ne.H;
  result.information = H_matched / (var * points_per_cell);
  result.covariance = 0.5 * (result.covariance + result.covariance.transpose()).eval();
  result.T_map_base = T;
  result.residual_rms = ne.n > 0 ? std::sqrt(ne.cost / ne.n) : 0.0;
  return result;
}

// The points' surface normals when the config matches across surfaces or weighs degeneracy, else
// null.
std::unique_ptr<std::vector<Eigen::Vector2d>> matching_normals(
    const std::vector<Eigen::Vector2d>& points_base, const MatcherConfig& config) {
  if (!config.normal_projection && config.degeneracy_min_ratio <= 0.0) return nullptr;
  return std::make_unique<std::vector<Eigen::Vector2d>>(surface_normals(points_base));
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
  const auto normals = matching_normals(points_base, config);
  MatchResult result = refine(maps, points_base, normals.get(), T_map_base_predicted,
                              T_map_base_predicted, config, first_level, last_level);
  // A coarse level's neighbouring basin (MatcherConfig::coarse_check_m): the finest level alone
  // from the prediction, the better fit on the finest grid kept. Where the scan leaves a direction
  // open (degeneracy.hpp) only with coarse_check_open_directions: the fit is flat along it, and
  // the prediction holds it.
  if (config.coarse_check_m > 0.0 && first_level > last_level) {
    const Pose2 d = between(T_map_base_predicted, result.T_map_base);
    if (d.translation().norm() > config.coarse_check_m &&
        (config.coarse_check_open_directions || config.degeneracy_min_ratio <= 0.0 ||
         analyse_degeneracy(result.information, points_rms_range_m(points_base),
                            config.degeneracy_min_ratio)
                 .directions == 0)) {
      const MatchResult fine = refine(maps, points_base, normals.get(), T_map_base_predicted,
                                      T_map_base_predicted, config, last_level, last_level);
      const int iterations = result.iterations + fine.iterations;
      if (fine.residual_rms < (1.0 - config.coarse_check_gain) * result.residual_rms) result = fine;
      result.iterations = iterations;
    }
  }
  if (result.residual_rms <= config.search_trigger_residual) return result;
  std::vector<Pose2> centres{T_map_base_predicted};
  centres.insert(centres.end(), other_centres.begin(), other_centres.end());
  int iterations = result.iterations;
  for (const Pose2& centre : centres) {
    const Pose2 T_start =
        search_pose(maps.level(first_level), points_base, centre, config.search_linear_window_m,
                    config.search_angular_window_rad);
    MatchResult candidate =
        refine(maps, points_base, normals.get(), T_start, centre, config, first_level, last_level);
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

MatchResult match_scan_wide(const MapPyramid& maps, const std::vector<Eigen::Vector2d>& points_base,
                            const std::vector<Pose2>& priors, const MatcherConfig& config,
                            const Pose2* T_last) {
  const int search_level = std::min(1, maps.levels() - 1);
  const StepPrior prior = T_last ? step_prior(config, *T_last) : StepPrior{};
  const WideSearchResult s =
      wide_search(maps.level(search_level), points_base, priors.front(),
                  config.wide_search_linear_window_m, config.wide_search_angular_window_rad, priors,
                  config.wide_search_temperature, T_last ? &prior : nullptr);
  const auto normals = matching_normals(points_base, config);
  MatchResult result = refine(maps, points_base, normals.get(), s.T_map_base, s.T_map_base, config,
                              maps.levels() - 1, 0);
  // The Gauss-Newton covariance is the curvature where it ended; the search's spread adds what
  // the scan leaves open beyond it (an axis it cannot tell, a second pose that fits as well).
  result.covariance += s.covariance;
  result.searched = true;
  return result;
}

}  // namespace traverse::frontend
