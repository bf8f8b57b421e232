#include "scan_refiner.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "config.hpp"

namespace traverse::backend {
namespace {

// Reference points hashed into square cells of `cell` metres: neighbours within one cell's
// distance are in the 3 x 3 cells around a point.
class PointHash {
 public:
  PointHash(const std::vector<Eigen::Vector2d>& points, double cell)
      : points_(points), cell_(cell) {
    for (int i = 0; i < static_cast<int>(points.size()); ++i)
      cells_[key(cell_of(points[i]))].push_back(i);
  }

  template <class F>
  void for_each_near(const Eigen::Vector2d& p, F&& f) const {
    const Eigen::Vector2i c = cell_of(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(key(c + Eigen::Vector2i(dx, dy)));
        if (it == cells_.end()) continue;
        for (int i : it->second) f(i);
      }
    }
  }

 private:
  Eigen::Vector2i cell_of(const Eigen::Vector2d& p) const {
    return Eigen::Vector2i(static_cast<int>(std::floor(p.x() / cell_)),
                           static_cast<int>(std::floor(p.y() / cell_)));
  }
  static uint64_t key(const Eigen::Vector2i& c) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(c.x())) << 32) |
           static_cast<uint32_t>(c.y());
  }

  const std::vector<Eigen::Vector2d>& points_;
  double cell_;
  std::unordered_map<uint64_t, std::vector<int>> cells_;
};

// Directions whose curvature is below this fraction of the largest are taken as unconstrained
// (along a featureless corridor only noise in the normals pulls): no step is taken along them.
// Curvatures are compared with the heading expressed as arc length at `lever_m` (the RMS range of
// the points), so metres and radians weigh alike.
constexpr double kMinCurvatureRatio = 1e-2;

struct Eigen3 {
  Eigen::Matrix3d vectors;  // of the scaled H
  Eigen::Vector3d values;   // raised to the floor; 0 marks an unconstrained direction
  Eigen::Vector3d scale;    // (1, 1, 1 / lever_m)
};

Eigen3 scaled_eigen(const Eigen::Matrix3d& H, double lever_m, bool zero_unconstrained) {
  Eigen3 e;
  e.scale = Eigen::Vector3d(1.0, 1.0, 1.0 / lever_m);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(e.scale.asDiagonal() * H *
                                                           e.scale.asDiagonal());
  e.vectors = eig.eigenvectors();
  const double floor = kMinCurvatureRatio * eig.eigenvalues().maxCoeff();
  for (int i = 0; i < 3; ++i) {
    const double l = eig.eigenvalues()(i);
    e.values(i) = l > floor ? l : (zero_unconstrained ? 0.0 : floor);
  }
  return e;
}

// The Gauss-Newton step H^-1 g, without a step along unconstrained directions.
Eigen::Vector3d solve_constrained(const Eigen::Matrix3d& H, const Eigen::Vector3d& g,
                                  double lever_m) {
  const Eigen3 e = scaled_eigen(H, lever_m, true);
  const Eigen::Vector3d gs = e.scale.asDiagonal() * g;
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (e.values(i) > 0.0) x += e.vectors.col(i) * (e.vectors.col(i).dot(gs) / e.values(i));
  }
  return e.scale.asDiagonal() * x;
}

// H^-1 with the unconstrained curvatures raised to the floor: finite, and wide along them.
Eigen::Matrix3d inverse_constrained(const Eigen::Matrix3d& H, double lever_m) {
  const Eigen3 e = scaled_eigen(H, lever_m, false);
  return e.scale.asDiagonal() * e.vectors * e.values.cwiseInverse().asDiagonal() *
         e.vectors.transpose() * e.scale.asDiagonal();
}

}  // namespace

std::optional<std::string> validate(const RefinerConfig& c) {
  ConfigCheck check;
  check.positive("normal_radius_m", c.normal_radius_m);
  check.require(c.max_line_thickness > 0.0 && c.max_line_thickness < 1.0, "max_line_thickness",
                "must be in (0, 1)");
  check.positive("min_line_gate_m", c.min_line_gate_m);
  check.require(c.max_correspondence_m >= c.min_line_gate_m, "max_correspondence_m",
                "must be at least min_line_gate_m");
  check.require(c.max_correspondence_m <= c.normal_radius_m, "max_correspondence_m",
                "must be at most normal_radius_m");
  check.positive("huber_m", c.huber_m);
  check.in_range("iterations", c.iterations, 1, 1000);
  check.require(c.min_inlier_fraction > 0.0 && c.min_inlier_fraction <= 1.0, "min_inlier_fraction",
                "must be in (0, 1]");
  check.positive("max_shift_m", c.max_shift_m);
  check.positive("max_turn_rad", c.max_turn_rad);
  check.require(c.covariance_scale >= 1.0, "covariance_scale", "must be at least 1");
  return check.problem();
}

RefineResult ScanRefiner::refine(const std::vector<Eigen::Vector2d>& reference,
                                 const std::vector<Eigen::Vector2d>& query,
                                 const Pose2& T_world_start) const {
  const RefinerConfig& c = config_;
  RefineResult result;
  result.T_world_query = T_world_start;
  if (reference.size() < 3 || query.size() < 3) return result;

  // A normal for every reference point whose neighbours lie on a line.
  const PointHash hash(reference, c.normal_radius_m);
  std::vector<Eigen::Vector2d> normal(reference.size(), Eigen::Vector2d::Zero());
  const double r2 = c.normal_radius_m * c.normal_radius_m;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    Eigen::Matrix2d second = Eigen::Matrix2d::Zero();
    int n = 0;
    hash.for_each_near(reference[i], [&](int j) {
      const Eigen::Vector2d d = reference[j] - reference[i];
      if (d.squaredNorm() > r2) return;
      mean += d;
      second += d * d.transpose();
      ++n;
    });
    if (n < 3) continue;
    mean /= n;
    const Eigen::Matrix2d cov = second / n - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    if (!(eig.eigenvalues()(1) > 0.0)) continue;
    if (std::sqrt(eig.eigenvalues()(0) / eig.eigenvalues()(1)) > c.max_line_thickness) continue;
    normal[i] = eig.eigenvectors().col(0);
  }

  double range_sq = 0.0;
  for (const Eigen::Vector2d& q : query) range_sq += q.squaredNorm();
  const double lever_m = std::max(std::sqrt(range_sq / static_cast<double>(query.size())), 0.1);

  Eigen::Vector3d x(T_world_start.x(), T_world_start.y(), T_world_start.theta());
  const double max_d = c.max_correspondence_m;
  double gate = max_d;  // largest point-to-line distance taken, shrinking with the residuals
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  double weighted_sq = 0.0, weight_sum = 0.0;
  int used = 0;
  for (int it = 0; it < c.iterations; ++it) {
    const double cs = std::cos(x.z()), sn = std::sin(x.z());
    H.setZero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    weighted_sq = weight_sum = 0.0;
    used = 0;
    double sq = 0.0;
    for (const Eigen::Vector2d& q : query) {
      const Eigen::Vector2d rq(cs * q.x() - sn * q.y(), sn * q.x() + cs * q.y());
      const Eigen::Vector2d w = rq + x.head<2>();
      int best = -1;
      double best_d2 = max_d * max_d;
      hash.for_each_near(w, [&](int j) {
        const double d2 = (reference[j] - w).squaredNorm();
        if (d2 < best_d2 && normal[j] != Eigen::Vector2d::Zero()) best_d2 = d2, best = j;
      });
      if (best < 0) continue;
      const Eigen::Vector2d& nrm = normal[best];
      const double r = nrm.dot(w - reference[best]);
      if (std::abs(r) > gate) continue;
      const Eigen::Vector3d J(nrm.x(), nrm.y(), nrm.dot(Eigen::Vector2d(-rq.y(), rq.x())));
      const double weight = std::abs(r) <= c.huber_m ? 1.0 : c.huber_m / std::abs(r);
      H += weight * J * J.transpose();
      g += weight * J * r;
      weighted_sq += weight * r * r;
      weight_sum += weight;
      sq += r * r;
      ++used;
    }
    result.iterations = it + 1;
    if (used < 3) return result;
    const Eigen::Vector3d delta = -solve_constrained(H, g, lever_m);
    if (!delta.allFinite()) return result;
    x += delta;
    // The next residuals within three RMS residuals, as long as that is not too tight.
    gate = std::clamp(3.0 * std::sqrt(sq / used), c.min_line_gate_m, max_d);
    if (delta.head<2>().norm() < 1e-6 && std::abs(delta.z()) < 1e-7) break;
  }

  result.inlier_fraction = static_cast<double>(used) / static_cast<double>(query.size());
  result.rms_residual_m = std::sqrt(weighted_sq / std::max(weight_sum, 1e-12));
  result.T_world_query = Pose2(x.x(), x.y(), x.z());
  const double shift = (result.T_world_query.translation() - T_world_start.translation()).norm();
  const double turn = std::abs(wrap_angle(x.z() - T_world_start.theta()));
  if (result.inlier_fraction < c.min_inlier_fraction || shift > c.max_shift_m ||
      turn > c.max_turn_rad) {
    result.T_world_query = T_world_start;
    return result;
  }
  const double dof = std::max(weight_sum - 3.0, 1.0);
  const double sigma2 = weighted_sq / dof;
  result.covariance = c.covariance_scale * sigma2 * inverse_constrained(H, lever_m);
  result.information = sigma2 > 0.0 ? H / (c.covariance_scale * sigma2) : H;
  result.lever_m = lever_m;
  result.valid = result.covariance.allFinite();
  if (!result.valid) result.T_world_query = T_world_start;
  return result;
}

}  // namespace traverse::backend
