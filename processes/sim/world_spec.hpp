// The world file format (configs/worlds/*.yaml): a 2.5D indoor or outdoor scene made of vertical
// walls given as polylines with a height range, round pillars, boxes, shelves, desks with legs,
// a floor and an optional ceiling, and named materials that say how a laser beam behaves on them.
// Loaded with traverse::load_config, so a misspelled key is an error naming the key and the file.
// Coordinates: frame "world", x east, y north, z up, metres; yaw in radians counter-clockwise.
#pragma once

#include <string>
#include <vector>

namespace traverse::sim {

// How a surface answers a laser beam.
struct MaterialSpec {
  std::string name;
  double reflectivity = 0.5;  // [0..1] diffuse reflectance at the scanners' wavelength
  // Of the beams that reach the surface: probability of a return from it, of a specular
  // (mirror) reflection that continues in the reflected direction, else the beam passes through
  // (glass). Opaque diffuse surfaces: p_return 1.
  double p_return = 1.0;
  double p_mirror = 0.0;
  template <class V>
  void visit(V& v) {
    v("name", name);
    v("reflectivity", reflectivity);
    v("p_return", p_return);
    v("p_mirror", p_mirror);
  }
};

// A wall: vertical faces along a polyline of [x, y] points, from z[0] to z[1].
struct WallSpec {
  std::vector<std::vector<double>> points;  // [m] [[x, y], ...] in world
  std::vector<double> z = {0.0, 2.8};       // [m] bottom, top
  bool closed = false;                      // also joins the last point to the first
  std::string material = "wall";
  template <class V>
  void visit(V& v) {
    v("points", points);
    v("z", z);
    v("closed", closed);
    v("material", material);
  }
};

// A round pillar (also tree trunks, poles).
struct PillarSpec {
  std::string id;                      // name used when pillars are checked (e.g. "P1")
  double x = 0.0, y = 0.0;             // [m] centre in world
  double radius = 0.2;                 // [m]
  std::vector<double> z = {0.0, 2.8};  // [m] bottom, top
  std::string material = "concrete";
  template <class V>
  void visit(V& v) {
    v("id", id);
    v("x", x);
    v("y", y);
    v("radius", radius);
    v("z", z);
    v("material", material);
  }
};

// A closed box (cabinets, counters, shelves full of books); also used for shelves.
struct BoxSpec {
  double x = 0.0, y = 0.0;               // [m] centre of the footprint in world
  double yaw = 0.0;                      // [rad] rotation of the footprint
  std::vector<double> size = {1, 1, 1};  // [m] length (along yaw), width, height
  double z0 = 0.0;                       // [m] bottom
  std::string material = "wood";
  template <class V>
  void visit(V& v) {
    v("x", x);
    v("y", y);
    v("yaw", yaw);
    v("size", size);
    v("z0", z0);
    v("material", material);
  }
};

// A desk or table: a top slab on four round legs set in from the corners.
struct DeskSpec {
  double x = 0.0, y = 0.0;                // [m] centre in world
  double yaw = 0.0;                       // [rad]
  std::vector<double> size = {1.6, 0.8};  // [m] length, width of the top
  double height = 0.74;                   // [m] top surface above the floor
  double top_thickness = 0.03;            // [m]
  double leg_radius = 0.025;              // [m]
  double leg_inset = 0.05;                // [m] leg centre from the top's edges
  std::string material = "wood";
  std::string leg_material = "metal";
  template <class V>
  void visit(V& v) {
    v("x", x);
    v("y", y);
    v("yaw", yaw);
    v("size", size);
    v("height", height);
    v("top_thickness", top_thickness);
    v("leg_radius", leg_radius);
    v("leg_inset", leg_inset);
    v("material", material);
    v("leg_material", leg_material);
  }
};

struct WorldSpec {
  std::string name;
  std::string description;
  double floor_z = 0.0;     // [m]
  double ceiling_z = -1.0;  // [m] below floor_z means no ceiling (outdoors)
  std::string floor_material = "floor";
  std::string ceiling_material = "ceiling";
  std::vector<MaterialSpec> materials;
  std::vector<WallSpec> walls;
  std::vector<PillarSpec> pillars;
  std::vector<BoxSpec> boxes;
  std::vector<BoxSpec> shelves;
  std::vector<DeskSpec> desks;
  template <class V>
  void visit(V& v) {
    v("name", name);
    v("description", description);
    v("floor_z", floor_z);
    v("ceiling_z", ceiling_z);
    v("floor_material", floor_material);
    v("ceiling_material", ceiling_material);
    v("materials", materials);
    v("walls", walls);
    v("pillars", pillars);
    v("boxes", boxes);
    v("shelves", shelves);
    v("desks", desks);
  }
};

}  // namespace traverse::sim
