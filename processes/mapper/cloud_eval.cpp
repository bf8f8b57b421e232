#include "cloud_eval.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>

#include "config.hpp"

namespace traverse::mapper {

void transform_cloud(std::vector<CloudPoint>& cloud, const Pose2& T_world_map) {
  const Eigen::Matrix2f R = T_world_map.rotation().cast<float>();
  const Eigen::Vector2f t = T_world_map.translation().cast<float>();
  for (CloudPoint& p : cloud) p.p_world.head<2>() = R * p.p_world.head<2>() + t;
}

Stats describe(std::vector<double> v, double bin) {
  Stats s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  double sum = 0, sq = 0;
  for (double x : v) sum += x, sq += x * x;
  s.mean = sum / s.n;
  s.rmse = std::sqrt(sq / s.n);
  s.sd = s.n > 1 ? std::sqrt(std::max(0.0, (sq - s.n * s.mean * s.mean) / (s.n - 1))) : 0.0;
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  s.p95 = v[std::min<std::size_t>(v.size() - 1, static_cast<std::size_t>(0.95 * v.size()))];
  if (bin > 0) {
    std::map<int64_t, int> hist;
    for (double x : v) ++hist[static_cast<int64_t>(std::floor(x / bin))];
    auto best = std::max_element(hist.begin(), hist.end(),
                                 [](const auto& a, const auto& b) { return a.second < b.second; });
    s.mode = (static_cast<double>(best->first) + 0.5) * bin;
  }
  return s;
}

std::optional<Eigen::Vector2d> fit_circle(const std::vector<Eigen::Vector2d>& pts,
                                          const Eigen::Vector2d& start, double radius,
                                          double trim_m) {
  Eigen::Vector2d c = start;
  for (int iter = 0; iter < 30; ++iter) {
    // Residual r_i = |p_i - c| - radius; dr/dc = -(p_i - c) / |p_i - c|.
    Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    int used = 0;
    for (const auto& p : pts) {
      const Eigen::Vector2d d = p - c;
      const double n = d.norm();
      if (n < 1e-9) continue;
      const double r = n - radius;
      if (iter > 0 && std::abs(r) > trim_m) continue;
      const Eigen::Vector2d J = -d / n;
      H += J * J.transpose();
      g += J * r;
      ++used;
    }
    if (used < 3 || std::abs(H.determinant()) < 1e-12) return std::nullopt;
    const Eigen::Vector2d step = -H.ldlt().solve(g);
    c += step;
    if (step.norm() < 1e-7) break;
  }
  return c;
}

std::optional<std::string> validate(const WallProbe& w) {
  ConfigCheck check;
  check.require(w.axis == "x" || w.axis == "y", "axis", "must be x or y, not '" + w.axis + "'");
  check.require(!w.across.empty(), "across", "needs at least one interval [lo, hi]");
  for (std::size_t i = 0; i < w.across.size(); ++i) {
    const std::vector<double>& iv = w.across[i];
    check.require(iv.size() == 2 && iv[0] < iv[1], "across[" + std::to_string(i) + "]",
                  "must be an interval [lo, hi] with lo < hi (metres)");
  }
  return check.problem();
}

std::optional<std::string> validate(const CloudEvalConfig& c) {
  ConfigCheck check;
  check.positive("max_search_m", c.max_search_m);
  check.positive("histogram_bin_m", c.histogram_bin_m);
  check.require(c.max_search_m / c.histogram_bin_m <= 1e7, "histogram_bin_m",
                "must be at least max_search_m / 1e7");
  check.positive("pillar_band_m", c.pillar_band_m);
  check.positive("pillar_trim_m", c.pillar_trim_m);
  check.in_range("pillar_min_points", c.pillar_min_points, 3, 1'000'000'000);
  check.require(c.z_max_m > c.z_min_m, "z_max_m", "must exceed z_min_m");
  check.positive("wall_band_m", c.wall_band_m);
  for (std::size_t i = 0; i < c.corridors.size(); ++i) {
    const std::string key = "corridors[" + std::to_string(i) + "]";
    check.nested(key + ".end_a", validate(c.corridors[i].end_a));
    check.nested(key + ".end_b", validate(c.corridors[i].end_b));
  }
  return check.problem();
}

namespace {

bool in_any(const std::vector<std::vector<double>>& intervals, double v) {
  for (const auto& iv : intervals) {
    if (v >= iv[0] && v <= iv[1]) return true;
  }
  return false;
}

// Median coordinate of the cloud points near the wall (nullopt below 20); `n` gets their number.
std::optional<double> wall_position(const std::vector<CloudPoint>& cloud, const WallProbe& w,
                                    const CloudEvalConfig& config, int& n) {
  const int along = w.axis == "y" ? 1 : 0, other = 1 - along;
  std::vector<double> v;
  for (const CloudPoint& p : cloud) {
    const double a = p.p_world[along], o = p.p_world[other], z = p.p_world.z();
    if (std::abs(a - w.at) < config.wall_band_m && in_any(w.across, o) && z >= config.z_min_m &&
        z <= config.z_max_m) {
      v.push_back(a);
    }
  }
  n = static_cast<int>(v.size());
  if (v.size() < 20) return std::nullopt;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

CloudEvalResult evaluate_cloud(const std::vector<CloudPoint>& cloud, const sim::World& world,
                               const sim::WorldSpec& spec, const CloudEvalConfig& config,
                               std::size_t stride) {
  CloudEvalResult out;
  std::vector<double> dist;
  stride = std::max<std::size_t>(stride, 1);
  dist.reserve(cloud.size() / stride + 1);
  for (std::size_t i = 0; i < cloud.size(); i += stride) {
    dist.push_back(world.distance_to_surface(cloud[i].p_world.cast<double>(), config.max_search_m));
  }
  out.surface = describe(std::move(dist), config.histogram_bin_m);

  std::vector<double> errors;
  for (const sim::PillarSpec& pillar : spec.pillars) {
    const Eigen::Vector2d c_true(pillar.x, pillar.y);
    std::vector<Eigen::Vector2d> pts;
    for (const CloudPoint& p : cloud) {
      const Eigen::Vector2d q(p.p_world.x(), p.p_world.y());
      const double z = p.p_world.z();
      if (z < config.z_min_m || z > config.z_max_m) continue;
      if (std::abs((q - c_true).norm() - pillar.radius) < config.pillar_band_m) pts.push_back(q);
    }
    PillarResult r{pillar.id, static_cast<int>(pts.size()), std::nullopt};
    if (r.points >= config.pillar_min_points) {
      // Start from the centroid of the points: for the arc the scanner sees it lies inside the
      // circle on the arc's side, nearer the true centre than the mirror solution behind the arc.
      Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
      for (const auto& q : pts) centroid += q;
      centroid /= static_cast<double>(pts.size());
      if (auto c = fit_circle(pts, centroid, pillar.radius, config.pillar_trim_m)) {
        r.error_m = (*c - c_true).norm();
        errors.push_back(*r.error_m);
      }
    }
    out.pillars.push_back(r);
  }
  out.pillar = describe(std::move(errors), 0.0);

  for (const CorridorSpec& c : config.corridors) {
    CorridorResult r{c.name, std::nullopt, std::abs(c.end_b.at - c.end_a.at), 0, 0};
    auto a = wall_position(cloud, c.end_a, config, r.points_a);
    auto b = wall_position(cloud, c.end_b, config, r.points_b);
    if (a && b) r.length_m = std::abs(*b - *a);
    out.corridors.push_back(r);
  }
  return out;
}

}  // namespace traverse::mapper
