// The true geometry of a simulated scene: the surfaces of a WorldSpec as vertical quads, vertical
// cylinder sections and horizontal rectangles, plus the floor and ceiling planes, with a uniform
// 2D grid over the footprints so that a ray visits only the cells it crosses (Amanatides and Woo,
// "A fast voxel traversal algorithm for ray tracing", 1987). Answers the two questions the
// simulator and the evaluators ask: where does a ray first meet a surface, and how far is a point
// from the nearest true surface.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "world_spec.hpp"

namespace traverse::sim {

struct Material {
  std::string name;
  double reflectivity = 0.5;
  double p_return = 1.0;
  double p_mirror = 0.0;
};

// The time an item exists [s since the route's start]: always, unless it is a movable.
struct Lifetime {
  double from = -std::numeric_limits<double>::infinity();
  double to = std::numeric_limits<double>::infinity();
  bool at(double t) const { return t >= from && t < to; }
};

// A vertical rectangle between a and b (world xy) from z0 to z1.
struct Face {
  Eigen::Vector2d a, b;
  double z0, z1;
  int material;
  Lifetime life{};
};

// The side of a vertical cylinder.
struct Cylinder {
  Eigen::Vector2d c;
  double r, z0, z1;
  int material;
  Lifetime life{};
};

// A horizontal rectangle at height z: centre, unit axis u (v = u rotated +90 deg), half sizes.
struct Slab {
  Eigen::Vector2d c, u;
  double hu, hv, z;
  int material;
  Lifetime life{};
};

struct RayHit {
  double t = 0.0;                                    // [m] along the unit direction
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, facing the ray
  int material = -1;
};

// Which of a WorldSpec's elements to build. By default every element of every layer and both
// passes of every movable (what an evaluator compares a cloud with); the simulator names its
// layers and, with world changes, the time each movable group swaps.
struct WorldOptions {
  std::optional<std::vector<std::string>> layers;  // nullopt: all layers
  // Movable group id -> swap time [s]; nullopt: every movable always (with layers == nullopt) or
  // first-pass movables only (with named layers).
  std::optional<std::map<std::string, double>> swap_times;
};

// True when an element with `layer` exists with the named layers (nullopt: every element).
bool layer_active(const std::string& layer, const std::optional<std::vector<std::string>>& layers);

// Ray-cylinder intersection with t in (t_min, best_t): on a hit, updates best_t and best.
void intersect_cylinder(const Cylinder& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                        double t_min, double& best_t, RayHit& best);

class World {
 public:
  // Throws std::runtime_error for inconsistent data (unknown material, bad sizes).
  explicit World(const WorldSpec& spec, double cell_size_m = 0.5, const WorldOptions& options = {});

  // Nearest intersection of origin + t * dir (dir unit length) with t in (t_min, t_max], with the
  // items that exist at `time_s` [s since the route's start].
  std::optional<RayHit> raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                double t_max, double t_min = 1e-6, double time_s = 0.0) const;

  // [m] Euclidean distance from p to the nearest true surface (floor and ceiling included),
  // searching surfaces within max_search_m; returns max_search_m when none is closer.
  double distance_to_surface(const Eigen::Vector3d& p, double max_search_m = 2.0) const;

  // [m] horizontal distance from (x, y) to the nearest obstacle whose height range overlaps
  // [z_lo, z_hi] (walls, pillars, furniture; not floor or ceiling), searching all objects (with
  // `time_s`, those that exist then).
  double clearance_2d(const Eigen::Vector2d& xy, double z_lo, double z_hi,
                      std::optional<double> time_s = std::nullopt) const;

  const std::string& name() const { return name_; }
  const Material& material(int i) const { return materials_[i]; }
  int material_index(const std::string& name) const;  // -1 if unknown
  double floor_z() const { return floor_z_; }
  std::optional<double> ceiling_z() const { return ceiling_z_; }
  const std::vector<Face>& faces() const { return faces_; }
  const std::vector<Cylinder>& cylinders() const { return cylinders_; }
  const std::vector<Slab>& slabs() const { return slabs_; }

 private:
  void add_box(const Eigen::Vector2d& c, double yaw, double lx, double ly, double z0, double z1,
               int material, Lifetime life = {});
  void build_grid();
  int cell_index(int ix, int iy) const { return iy * nx_ + ix; }
  // Tests every item in cell `cell` that exists at `time_s` against the ray, keeping the nearest
  // hit in `best`.
  void test_cell(int cell, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_min,
                 double time_s, double& best_t, RayHit& best) const;

  std::string name_;
  std::vector<Material> materials_;
  std::vector<Face> faces_;
  std::vector<Cylinder> cylinders_;
  std::vector<Slab> slabs_;
  double floor_z_ = 0.0;
  std::optional<double> ceiling_z_;
  int floor_material_ = 0, ceiling_material_ = 0;

  // Grid: items of cell k are items_[cell_start_[k] .. cell_start_[k+1]); an item id encodes
  // its kind in the top two bits (0 face, 1 cylinder, 2 slab).
  double cell_ = 0.5;
  Eigen::Vector2d grid_min_ = Eigen::Vector2d::Zero();
  int nx_ = 0, ny_ = 0;
  std::vector<uint32_t> cell_start_;
  std::vector<uint32_t> items_;
};

}  // namespace traverse::sim
