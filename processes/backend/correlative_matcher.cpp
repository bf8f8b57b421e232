#include "correlative_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace traverse::backend {
namespace {

// The lookup table of section III-B and its block maxima (section IV), on one index space: the
// coarse value at (ix, iy) is the maximum fine value over [ix, ix + k) x [iy, iy + k).
class LookupTable {
 public:
  LookupTable(const std::vector<Eigen::Vector2d>& points, double resolution, double sigma,
              int coarse_factor, double margin)
      : resolution_(resolution), coarse_factor_(coarse_factor) {
    Eigen::Vector2d lo = points.front(), hi = points.front();
    for (const auto& p : points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    origin_ = lo - Eigen::Vector2d::Constant(margin);
    width_ = static_cast<int>(std::ceil((hi.x() - lo.x() + 2 * margin) / resolution)) + 1;
    height_ = static_cast<int>(std::ceil((hi.y() - lo.y() + 2 * margin) / resolution)) + 1;
    fine_.assign(static_cast<std::size_t>(width_) * height_, 0.0f);
    const int radius = static_cast<int>(std::ceil(3.0 * sigma / resolution));
    stamp_all(points, radius, sigma);
    build_coarse(coarse_factor);
  }

  Eigen::Vector2i index(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d c = (p - origin_) / resolution_;
    return {static_cast<int>(std::floor(c.x())), static_cast<int>(std::floor(c.y()))};
  }
  float fine(int x, int y) const { return inside(x, y) ? fine_[at(x, y)] : 0.0f; }
  // A block starting left of or below the table still covers its first cells: clamping the start
  // keeps the value an upper bound.
  float coarse(int x, int y) const {
    if (x < 0 && x > -coarse_factor_) x = 0;
    if (y < 0 && y > -coarse_factor_) y = 0;
    return inside(x, y) ? coarse_[at(x, y)] : 0.0f;
  }

 private:
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  std::size_t at(int x, int y) const { return static_cast<std::size_t>(y) * width_ + x; }

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
      const Eigen::Vector2i c = index(p);
      for (int dy = -radius; dy <= radius; ++dy) {
        const int y = c.y() + dy;
        if (y < 0 || y >= height_) continue;
        for (int dx = -radius; dx <= radius; ++dx) {
          const int x = c.x() + dx;
          if (x < 0 || x >= width_) continue;
          float& v = fine_[at(x, y)];
          v = std::max(v, kernel[(dy + radius) * side + dx + radius]);
        }
      }
    }
  }

  // Separable sliding maximum over k cells towards +x, then towards +y.
  void build_coarse(int k) {
    std::vector<float> rows(fine_.size(), 0.0f);
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        float m = 0.0f;
        for (int d = 0; d < k && x + d < width_; ++d) m = std::max(m, fine_[at(x + d, y)]);
        rows[at(x, y)] = m;
      }
    }
    coarse_.assign(fine_.size(), 0.0f);
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        float m = 0.0f;
        for (int d = 0; d < k && y + d < height_; ++d) m = std::max(m, rows[at(x, y + d)]);
        coarse_[at(x, y)] = m;
      }
    }
  }

  double resolution_;
  int coarse_factor_;
  Eigen::Vector2d origin_;
  int width_ = 0, height_ = 0;
  std::vector<float> fine_, coarse_;
};

// [cells] the largest lookup table built (4 bytes a cell, twice): 256 MB.
constexpr double kMaxTableCells = 32.0 * 1024 * 1024;

struct Candidate {
  double bound;  // upper bound of the (penalised or raw) response in the block
  int angle;     // heading step index in [0, 2A]
  int i0, j0;    // first translation step of the block, in [-W, W]
};

}  // namespace

std::string validate(const CorrelativeMatcherConfig& c) {
  if (!(c.resolution_m > 0.0)) return "resolution_m must be > 0";
  if (c.coarse_factor < 1) return "coarse_factor must be >= 1";
  if (!(c.angle_step_rad > 0.0)) return "angle_step_rad must be > 0";
  if (c.linear_window_m < 0.0 || c.angular_window_rad < 0.0) return "windows must be >= 0";
  if (!(c.kernel_sigma_m > 0.0)) return "kernel_sigma_m must be > 0";
  if (!(c.penalty_sigma_xy_m > 0.0) || !(c.penalty_sigma_theta_rad > 0.0)) {
    return "penalty sigmas must be > 0";
  }
  if (c.covariance_response_drop < 0.0) return "covariance_response_drop must be >= 0";
  if (c.covariance_window_cells < 1) return "covariance_window_cells must be >= 1";
  if (c.max_query_points < 1) return "max_query_points must be >= 1";
  return {};
}

CorrelativeMatcher::CorrelativeMatcher(CorrelativeMatcherConfig config)
    : config_(std::move(config)) {}

MatchResult CorrelativeMatcher::match(const std::vector<Eigen::Vector2d>& reference_all,
                                      const std::vector<Eigen::Vector2d>& query_all,
                                      const Pose2& T_world_guess,
                                      double second_peak_exclusion_m) const {
  MatchResult result;
  if (reference_all.empty() || query_all.empty()) return result;
  if (!Eigen::Vector3d(T_world_guess.x(), T_world_guess.y(), T_world_guess.theta()).allFinite()) {
    return result;
  }
  const CorrelativeMatcherConfig& c = config_;
  const double res = c.resolution_m, step = c.angle_step_rad;
  const int k = c.coarse_factor;
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
  reach += std::sqrt(2.0) * (W + k) * res + 2.0 * margin;
  if (std::pow(2.0 * reach / res, 2) > kMaxTableCells) return result;
  std::vector<Eigen::Vector2d> reference_world;
  for (const Eigen::Vector2d& p : reference_all) {
    if (p.allFinite() && (p - T_world_guess.translation()).cwiseAbs().maxCoeff() <= reach) {
      reference_world.push_back(p);
    }
  }
  if (reference_world.empty()) return result;
  const LookupTable table(reference_world, res, c.kernel_sigma_m, k, margin);

  // Table index of every query point at each heading, translated by the guess (section IV: the
  // rotation is applied once per heading, translations are index offsets).
  std::vector<std::vector<Eigen::Vector2i>> indices(2 * A + 1);
  for (int a = 0; a <= 2 * A; ++a) {
    const Pose2 T(T_world_guess.x(), T_world_guess.y(), T_world_guess.theta() + (a - A) * step);
    indices[a].reserve(query.size());
    for (const auto& p : query) indices[a].push_back(table.index(T * p));
  }
  const auto penalty = [&](double di2_cells, int a) {
    const double dth = (a - A) * step;
    return std::exp(-0.5 * (di2_cells * res * res / (c.penalty_sigma_xy_m * c.penalty_sigma_xy_m) +
                            dth * dth / (c.penalty_sigma_theta_rad * c.penalty_sigma_theta_rad)));
  };
  const auto fine_sum = [&](int a, int i, int j) {
    double s = 0.0;
    for (const auto& q : indices[a]) s += table.fine(q.x() + i, q.y() + j);
    return s / n;
  };
  // Smallest |v| over v in [lo, hi].
  const auto closest = [](int lo, int hi) { return lo > 0 ? lo : (hi < 0 ? -hi : 0); };

  // Coarse pass: one bound per block and heading.
  std::vector<Candidate> penalised, raw;
  for (int a = 0; a <= 2 * A; ++a) {
    for (int i0 = -W; i0 <= W; i0 += k) {
      for (int j0 = -W; j0 <= W; j0 += k) {
        double s = 0.0;
        for (const auto& q : indices[a]) s += table.coarse(q.x() + i0, q.y() + j0);
        s /= n;
        const int ci = closest(i0, std::min(i0 + k - 1, W));
        const int cj = closest(j0, std::min(j0 + k - 1, W));
        penalised.push_back({s * penalty(ci * ci + cj * cj, a), a, i0, j0});
        raw.push_back({s, a, i0, j0});
      }
    }
  }
  result.evaluations = static_cast<long>(penalised.size());
  const auto by_bound = [](const Candidate& x, const Candidate& y) { return x.bound > y.bound; };

  // Fine pass, best-first, until no block can beat the best.
  std::sort(penalised.begin(), penalised.end(), by_bound);
  double best = -1.0;
  int best_a = A, best_i = 0, best_j = 0;
  for (const Candidate& cand : penalised) {
    if (cand.bound <= best) break;
    for (int i = cand.i0; i < cand.i0 + k && i <= W; ++i) {
      for (int j = cand.j0; j < cand.j0 + k && j <= W; ++j) {
        ++result.evaluations;
        const double s = fine_sum(cand.angle, i, j) * penalty(i * i + j * j, cand.angle);
        if (s > best) best = s, best_a = cand.angle, best_i = i, best_j = j;
      }
    }
  }
  result.valid = true;
  result.response = best;
  result.raw_response = fine_sum(best_a, best_i, best_j);
  // Sub-step refinement: the vertex of a parabola through the best pose and its two neighbours,
  // per axis (the table is smooth at the kernel scale, so the peak is locally quadratic).
  const auto score = [&](int a, int i, int j) {
    if (a < 0 || a > 2 * A || std::abs(i) > W || std::abs(j) > W) return -1.0;
    return fine_sum(a, i, j) * penalty(i * i + j * j, a);
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

  // Second peak: the same search on raw responses, skipping poses near the best translation.
  if (second_peak_exclusion_m > 0.0) {
    const double excl2 = std::pow(second_peak_exclusion_m / res, 2);
    const auto far = [&](int i, int j) {
      return (i - best_i) * (i - best_i) + (j - best_j) * (j - best_j) >= excl2;
    };
    std::sort(raw.begin(), raw.end(), by_bound);
    double second = 0.0;
    for (const Candidate& cand : raw) {
      if (cand.bound <= second) break;
      for (int i = cand.i0; i < cand.i0 + k && i <= W; ++i) {
        for (int j = cand.j0; j < cand.j0 + k && j <= W; ++j) {
          if (!far(i, j)) continue;
          ++result.evaluations;
          second = std::max(second, fine_sum(cand.angle, i, j));
        }
      }
    }
    result.second_peak_response = second;
  }

  // Covariance from the spread of the response around the best pose (section III-D).
  const int cw = c.covariance_window_cells;
  double wsum = 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();
  for (int a = std::max(0, best_a - cw); a <= std::min(2 * A, best_a + cw); ++a) {
    for (int i = std::max(-W, best_i - cw); i <= std::min(W, best_i + cw); ++i) {
      for (int j = std::max(-W, best_j - cw); j <= std::min(W, best_j + cw); ++j) {
        ++result.evaluations;
        const double s = fine_sum(a, i, j) * penalty(i * i + j * j, a);
        if (s < best - c.covariance_response_drop) continue;
        const Eigen::Vector3d x((i - best_i) * res, (j - best_j) * res, (a - best_a) * step);
        wsum += s;
        mean += s * x;
        second_moment += s * x * x.transpose();
      }
    }
  }
  if (wsum > 0.0) {
    mean /= wsum;
    result.covariance = second_moment / wsum - mean * mean.transpose();
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
