#include "world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace traverse::sim {
namespace {

constexpr uint32_t kFace = 0u << 30, kCylinder = 1u << 30, kSlab = 2u << 30;
constexpr uint32_t kKindMask = 3u << 30;
constexpr double kInf = std::numeric_limits<double>::infinity();

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Distance from p to the segment a-b in the plane.
double point_segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                              const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a;
  const double len2 = e.squaredNorm();
  const double u = len2 > 0.0 ? std::clamp((p - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (a + u * e - p).norm();
}

// Height outside [z0, z1], zero inside.
double z_excess(double z, double z0, double z1) { return std::max({0.0, z0 - z, z - z1}); }

// Distance from p to the rectangle of a slab in the plane (zero inside).
double slab_plane_distance(const Slab& s, const Eigen::Vector2d& p) {
  const Eigen::Vector2d q = p - s.c;
  const Eigen::Vector2d v(-s.u.y(), s.u.x());
  const double eu = std::max(0.0, std::abs(q.dot(s.u)) - s.hu);
  const double ev = std::max(0.0, std::abs(q.dot(v)) - s.hv);
  return std::hypot(eu, ev);
}

// True when segment a-b touches the axis-aligned box [lo, hi] (Liang-Barsky clipping).
bool segment_touches_box(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                         const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  double t0 = 0.0, t1 = 1.0;
  const Eigen::Vector2d d = b - a;
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (a[k] < lo[k] || a[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

bool layer_active(const std::string& layer, const std::optional<std::vector<std::string>>& layers) {
  if (layer.empty() || !layers) return true;
  const bool negated = layer[0] == '!';
  const std::string name = negated ? layer.substr(1) : layer;
  const bool named = std::find(layers->begin(), layers->end(), name) != layers->end();
  return negated != named;
}

void intersect_cylinder(const Cylinder& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                        double t_min, double& best_t, RayHit& best) {
  const Eigen::Vector2d f = o.head<2>() - c.c, dxy = d.head<2>();
  const double a = dxy.squaredNorm();
  if (a < 1e-18) return;
  const double b = f.dot(dxy), cc = f.squaredNorm() - c.r * c.r;
  const double disc = b * b - a * cc;
  if (disc < 0.0) return;
  const double sq = std::sqrt(disc);
  for (const double t : {(-b - sq) / a, (-b + sq) / a}) {
    if (t <= t_min || t >= best_t) continue;
    const double z = o.z() + t * d.z();
    if (z < c.z0 || z > c.z1) continue;
    const Eigen::Vector2d q = o.head<2>() + t * dxy - c.c;
    Eigen::Vector3d n(q.x() / c.r, q.y() / c.r, 0.0);
    if (n.dot(d) > 0) n = -n;
    best_t = t;
    best = {t, n, c.material};
    return;
  }
}

World::World(const WorldSpec& spec, double cell_size_m, const WorldOptions& options)
    : name_(spec.name), cell_(cell_size_m) {
  const auto& layers = options.layers;
  for (const auto& m : spec.materials) {
    if (m.reflectivity < 0.0 || m.reflectivity > 1.0 || m.p_return < 0.0 || m.p_mirror < 0.0 ||
        m.p_return + m.p_mirror > 1.0 + 1e-9)
      throw std::runtime_error("material '" + m.name +
                               "': reflectivity and probabilities in [0, 1]");
    materials_.push_back({m.name, m.reflectivity, m.p_return, m.p_mirror});
  }
  auto mat = [&](const std::string& n) {
    const int i = material_index(n);
    if (i < 0) throw std::runtime_error("world '" + name_ + "': unknown material '" + n + "'");
    return i;
  };
  auto zrange = [&](const std::vector<double>& z, const std::string& what) {
    if (z.size() != 2 || z[1] <= z[0])
      throw std::runtime_error("world '" + name_ + "': " + what + " needs z: [bottom, top]");
    return std::pair{z[0], z[1]};
  };
  floor_z_ = spec.floor_z;
  floor_material_ = mat(spec.floor_material);
  if (spec.ceiling_z > spec.floor_z) {
    ceiling_z_ = spec.ceiling_z;
    ceiling_material_ = mat(spec.ceiling_material);
  }
  for (const auto& w : spec.walls) {
    if (!layer_active(w.layer, layers)) continue;
    const auto [z0, z1] = zrange(w.z, "a wall");
    const int m = mat(w.material);
    std::vector<Eigen::Vector2d> pts;
    for (const auto& p : w.points) {
      if (p.size() != 2) throw std::runtime_error("world '" + name_ + "': wall point needs [x, y]");
      pts.emplace_back(p[0], p[1]);
    }
    if (pts.size() < 2) throw std::runtime_error("world '" + name_ + "': wall needs 2+ points");
    for (std::size_t i = 0; i + 1 < pts.size(); ++i)
      faces_.push_back({pts[i], pts[i + 1], z0, z1, m});
    if (w.closed && pts.size() > 2) faces_.push_back({pts.back(), pts.front(), z0, z1, m});
  }
  for (const auto& p : spec.pillars) {
    if (!layer_active(p.layer, layers)) continue;
    const auto [z0, z1] = zrange(p.z, "pillar " + p.id);
    if (p.radius <= 0.0) throw std::runtime_error("pillar " + p.id + ": radius must be > 0");
    cylinders_.push_back({{p.x, p.y}, p.radius, z0, z1, mat(p.material)});
  }
  auto box = [&](const BoxSpec& b, Lifetime life) {
    if (b.size.size() != 3 || b.size[0] <= 0 || b.size[1] <= 0 || b.size[2] <= 0)
      throw std::runtime_error("world '" + name_ + "': box size needs [length, width, height]");
    add_box({b.x, b.y}, b.yaw, b.size[0], b.size[1], b.z0, b.z0 + b.size[2], mat(b.material), life);
  };
  for (const auto* list : {&spec.boxes, &spec.shelves})
    for (const auto& b : *list)
      if (layer_active(b.layer, layers)) box(b, {});
  for (const auto& d : spec.desks) {
    if (!layer_active(d.layer, layers)) continue;
    if (d.size.size() != 2) throw std::runtime_error("world '" + name_ + "': desk size [l, w]");
    const Eigen::Vector2d c(d.x, d.y), u(std::cos(d.yaw), std::sin(d.yaw)), v(-u.y(), u.x());
    const double top0 = floor_z_ + d.height - d.top_thickness;
    add_box(c, d.yaw, d.size[0], d.size[1], top0, floor_z_ + d.height, mat(d.material));
    const double lu = d.size[0] / 2 - d.leg_inset, lv = d.size[1] / 2 - d.leg_inset;
    for (const double su : {-1.0, 1.0})
      for (const double sv : {-1.0, 1.0})
        cylinders_.push_back(
            {c + su * lu * u + sv * lv * v, d.leg_radius, floor_z_, top0, mat(d.leg_material)});
  }
  for (const auto& m : spec.movables) {
    if (m.pass != "first" && m.pass != "second")
      throw std::runtime_error("world '" + name_ + "': movable '" + m.id +
                               "' needs pass: first or second");
    if (!layer_active(m.box.layer, layers)) continue;
    const bool first = m.pass == "first";
    Lifetime life;  // every movable always: the union an evaluator compares with
    if (options.swap_times) {
      const auto it = options.swap_times->find(m.id);
      const double swap = it == options.swap_times->end() ? kInf : it->second;
      (first ? life.to : life.from) = swap;
    } else if (layers && !first) {
      continue;  // named layers without world changes: the first pass only
    }
    box(m.box, life);
  }
  build_grid();
}

int World::material_index(const std::string& name) const {
  for (std::size_t i = 0; i < materials_.size(); ++i)
    if (materials_[i].name == name) return static_cast<int>(i);
  return -1;
}

void World::add_box(const Eigen::Vector2d& c, double yaw, double lx, double ly, double z0,
                    double z1, int material, Lifetime life) {
  const Eigen::Vector2d u(std::cos(yaw), std::sin(yaw)), v(-u.y(), u.x());
  const Eigen::Vector2d p[4] = {c - lx / 2 * u - ly / 2 * v, c + lx / 2 * u - ly / 2 * v,
                                c + lx / 2 * u + ly / 2 * v, c - lx / 2 * u + ly / 2 * v};
  for (int i = 0; i < 4; ++i) faces_.push_back({p[i], p[(i + 1) % 4], z0, z1, material, life});
  slabs_.push_back({c, u, lx / 2, ly / 2, z1, material, life});
  if (z0 > floor_z_ + 1e-6) slabs_.push_back({c, u, lx / 2, ly / 2, z0, material, life});
}

void World::build_grid() {
  // Footprint bounding box of every item, per item.
  struct Box {
    Eigen::Vector2d lo, hi;
  };
  std::vector<std::pair<uint32_t, Box>> boxes;
  for (uint32_t i = 0; i < faces_.size(); ++i)
    boxes.push_back(
        {kFace | i, {faces_[i].a.cwiseMin(faces_[i].b), faces_[i].a.cwiseMax(faces_[i].b)}});
  for (uint32_t i = 0; i < cylinders_.size(); ++i) {
    const auto& c = cylinders_[i];
    const Eigen::Vector2d r(c.r, c.r);
    boxes.push_back({kCylinder | i, {c.c - r, c.c + r}});
  }
  for (uint32_t i = 0; i < slabs_.size(); ++i) {
    const auto& s = slabs_[i];
    const Eigen::Vector2d v(-s.u.y(), s.u.x());
    const Eigen::Vector2d h = (s.u * s.hu).cwiseAbs() + (v * s.hv).cwiseAbs();
    boxes.push_back({kSlab | i, {s.c - h, s.c + h}});
  }
  Eigen::Vector2d lo(0, 0), hi(1, 1);
  if (!boxes.empty()) {
    lo = boxes[0].second.lo;
    hi = boxes[0].second.hi;
    for (const auto& [id, b] : boxes) {
      lo = lo.cwiseMin(b.lo);
      hi = hi.cwiseMax(b.hi);
    }
  }
  grid_min_ = lo - Eigen::Vector2d(cell_, cell_);
  nx_ = static_cast<int>(std::ceil((hi.x() - grid_min_.x()) / cell_)) + 1;
  ny_ = static_cast<int>(std::ceil((hi.y() - grid_min_.y()) / cell_)) + 1;

  std::vector<std::vector<uint32_t>> cells(static_cast<std::size_t>(nx_) * ny_);
  const double eps = 1e-9;
  for (const auto& [id, b] : boxes) {
    const int x0 = static_cast<int>(std::floor((b.lo.x() - grid_min_.x()) / cell_));
    const int x1 = static_cast<int>(std::floor((b.hi.x() - grid_min_.x()) / cell_));
    const int y0 = static_cast<int>(std::floor((b.lo.y() - grid_min_.y()) / cell_));
    const int y1 = static_cast<int>(std::floor((b.hi.y() - grid_min_.y()) / cell_));
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) {
        if ((id & kKindMask) == kFace) {
          const Face& f = faces_[id & ~kKindMask];
          const Eigen::Vector2d clo = grid_min_ + cell_ * Eigen::Vector2d(ix, iy);
          const Eigen::Vector2d e(eps, eps);
          if (!segment_touches_box(f.a, f.b, clo - e, clo + Eigen::Vector2d(cell_, cell_) + e))
            continue;
        }
        cells[cell_index(ix, iy)].push_back(id);
      }
    }
  }
  cell_start_.assign(cells.size() + 1, 0);
  for (std::size_t k = 0; k < cells.size(); ++k)
    cell_start_[k + 1] = cell_start_[k] + static_cast<uint32_t>(cells[k].size());
  items_.clear();
  items_.reserve(cell_start_.back());
  for (const auto& c : cells) items_.insert(items_.end(), c.begin(), c.end());
}

void World::test_cell(int cell, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                      double time_s, double& best_t, RayHit& best) const {
  const Eigen::Vector2d oxy = o.head<2>(), dxy = d.head<2>();
  for (uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
    const uint32_t id = items_[k];
    const uint32_t i = id & ~kKindMask;
    switch (id & kKindMask) {
      case kFace: {
        const Face& f = faces_[i];
        if (!f.life.at(time_s)) break;
        const Eigen::Vector2d e = f.b - f.a;
        const double denom = cross(dxy, e);
        if (std::abs(denom) < 1e-15) break;
        const Eigen::Vector2d w = f.a - oxy;
        const double t = cross(w, e) / denom;
        if (t <= t_min || t >= best_t) break;
        const double u = cross(w, dxy) / denom;
        if (u < 0.0 || u > 1.0) break;
        const double z = o.z() + t * d.z();
        if (z < f.z0 || z > f.z1) break;
        Eigen::Vector3d n(e.y(), -e.x(), 0.0);
        n /= e.norm();
        if (n.dot(d) > 0) n = -n;
        best_t = t;
        best = {t, n, f.material};
        break;
      }
      case kCylinder: {
        const Cylinder& c = cylinders_[i];
        if (c.life.at(time_s)) intersect_cylinder(c, o, d, t_min, best_t, best);
        break;
      }
      default: {
        const Slab& s = slabs_[i];
        if (!s.life.at(time_s) || std::abs(d.z()) < 1e-12) break;
        const double t = (s.z - o.z()) / d.z();
        if (t <= t_min || t >= best_t) break;
        const Eigen::Vector2d q = oxy + t * dxy - s.c;
        if (std::abs(q.dot(s.u)) > s.hu || std::abs(cross(s.u, q)) > s.hv) break;
        best_t = t;
        best = {t, Eigen::Vector3d(0, 0, d.z() > 0 ? -1.0 : 1.0), s.material};
        break;
      }
    }
  }
}

std::optional<RayHit> World::raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                     double t_max, double t_min, double time_s) const {
  double best_t = t_max;
  RayHit best;
  // Floor and ceiling are unbounded planes.
  if (d.z() < -1e-12) {
    const double t = (floor_z_ - o.z()) / d.z();
    if (t > t_min && t < best_t) {
      best_t = t;
      best = {t, Eigen::Vector3d(0, 0, 1), floor_material_};
    }
  } else if (d.z() > 1e-12 && ceiling_z_) {
    const double t = (*ceiling_z_ - o.z()) / d.z();
    if (t > t_min && t < best_t) {
      best_t = t;
      best = {t, Eigen::Vector3d(0, 0, -1), ceiling_material_};
    }
  }
  // Clip the ray's footprint to the grid, then walk the cells it crosses in order.
  const Eigen::Vector2d gmax = grid_min_ + cell_ * Eigen::Vector2d(nx_, ny_);
  double t0 = t_min, t1 = best_t;
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (o[k] < grid_min_[k] || o[k] >= gmax[k]) t1 = -1.0;
      continue;
    }
    double ta = (grid_min_[k] - o[k]) / d[k], tb = (gmax[k] - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 <= t1) {
    const Eigen::Vector2d p = o.head<2>() + t0 * d.head<2>();
    int ix = std::clamp(static_cast<int>(std::floor((p.x() - grid_min_.x()) / cell_)), 0, nx_ - 1);
    int iy = std::clamp(static_cast<int>(std::floor((p.y() - grid_min_.y()) / cell_)), 0, ny_ - 1);
    const int sx = d.x() > 0 ? 1 : -1, sy = d.y() > 0 ? 1 : -1;
    auto next_boundary = [&](int k, int i, int s) {
      if (std::abs(d[k]) < 1e-15) return kInf;
      return (grid_min_[k] + (i + (s > 0 ? 1 : 0)) * cell_ - o[k]) / d[k];
    };
    double tx = next_boundary(0, ix, sx), ty = next_boundary(1, iy, sy);
    const double dtx = std::abs(d.x()) < 1e-15 ? kInf : cell_ / std::abs(d.x());
    const double dty = std::abs(d.y()) < 1e-15 ? kInf : cell_ / std::abs(d.y());
    while (true) {
      test_cell(cell_index(ix, iy), o, d, t_min, time_s, best_t, best);
      const double t_exit = std::min(tx, ty);
      if (best_t <= t_exit || t_exit >= t1) break;
      if (tx < ty) {
        ix += sx;
        tx += dtx;
        if (ix < 0 || ix >= nx_) break;
      } else {
        iy += sy;
        ty += dty;
        if (iy < 0 || iy >= ny_) break;
      }
    }
  }
  if (best.material < 0) return std::nullopt;
  return best;
}

double World::distance_to_surface(const Eigen::Vector3d& p, double max_search_m) const {
  double best = std::min(max_search_m, std::abs(p.z() - floor_z_));
  if (ceiling_z_) best = std::min(best, std::abs(p.z() - *ceiling_z_));
  const Eigen::Vector2d xy = p.head<2>();
  const int x0 = std::max(0, static_cast<int>(std::floor((xy.x() - best - grid_min_.x()) / cell_)));
  const int x1 =
      std::min(nx_ - 1, static_cast<int>(std::floor((xy.x() + best - grid_min_.x()) / cell_)));
  const int y0 = std::max(0, static_cast<int>(std::floor((xy.y() - best - grid_min_.y()) / cell_)));
  const int y1 =
      std::min(ny_ - 1, static_cast<int>(std::floor((xy.y() + best - grid_min_.y()) / cell_)));
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const int cell = cell_index(ix, iy);
      for (uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const uint32_t id = items_[k], i = id & ~kKindMask;
        double dist = kInf;
        if ((id & kKindMask) == kFace) {
          const Face& f = faces_[i];
          dist = std::hypot(point_segment_distance(xy, f.a, f.b), z_excess(p.z(), f.z0, f.z1));
        } else if ((id & kKindMask) == kCylinder) {
          const Cylinder& c = cylinders_[i];
          const double radial = (xy - c.c).norm() - c.r;
          // Inside the solid the nearest surface is the side or a lid (lids are not surfaces
          // unless they are slabs, so only the side counts).
          dist = std::hypot(std::abs(radial), z_excess(p.z(), c.z0, c.z1));
        } else {
          const Slab& s = slabs_[i];
          dist = std::hypot(slab_plane_distance(s, xy), p.z() - s.z);
        }
        best = std::min(best, dist);
      }
    }
  }
  return best;
}

double World::clearance_2d(const Eigen::Vector2d& xy, double z_lo, double z_hi,
                           std::optional<double> time_s) const {
  double best = kInf;
  auto counts = [&](double z0, double z1, const Lifetime& life) {
    return z0 <= z_hi && z1 >= z_lo && (!time_s || life.at(*time_s));
  };
  for (const auto& f : faces_)
    if (counts(f.z0, f.z1, f.life)) best = std::min(best, point_segment_distance(xy, f.a, f.b));
  for (const auto& c : cylinders_)
    if (counts(c.z0, c.z1, c.life)) best = std::min(best, std::max(0.0, (xy - c.c).norm() - c.r));
  for (const auto& s : slabs_)
    if (counts(s.z, s.z, s.life)) best = std::min(best, slab_plane_distance(s, xy));
  return best;
}

}  // namespace traverse::sim
