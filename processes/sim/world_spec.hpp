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
  std::string layer;  // see WorldSpec: "" always, "NAME" only with layer NAME, "!NAME" only without
  template <class V>
  void visit(V& v) {
    v("points", points);
    v("z", z);
    v("closed", closed);
    v("material", material);
    v("layer", layer);
  }
};

// A round pillar (also tree trunks, poles).
struct PillarSpec {
  std::string id;                      // name used when pillars are checked (e.g. "P1")
  double x = 0.0, y = 0.0;             // [m] centre in world
  double radius = 0.2;                 // [m]
  std::vector<double> z = {0.0, 2.8};  // [m] bottom, top
  std::string material = "concrete";
  std::string layer;
  template <class V>
  void visit(V& v) {
    v("id", id);
    v("x", x);
    v("y", y);
    v("radius", radius);
    v("z", z);
    v("material", material);
    v("layer", layer);
  }
};

// A closed box (cabinets, counters, shelves full of books); also used for shelves.
struct BoxSpec {
  double x = 0.0, y = 0.0;               // [m] centre of the footprint in world
  double yaw = 0.0;                      // [rad] rotation of the footprint
  std::vector<double> size = {1, 1, 1};  // [m] length (along yaw), width, height
  double z0 = 0.0;                       // [m] bottom
  std::string material = "wood";
  std::string layer;
  template <class V>
  void visit(V& v) {
    v("x", x);
    v("y", y);
    v("yaw", yaw);
    v("size", size);
    v("z0", z0);
    v("material", material);
    v("layer", layer);
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
  std::string layer;
  template <class V>
  void visit(V& v) {
    v("layer", layer);
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

// A box that is there on only one pass of a place (a door closed on the second pass, a chair
// moved): with the simulator's world changes, `pass: first` boxes vanish and `pass: second` boxes
// appear between the cart's first and second visit near them (boxes sharing an `id` swap at the
// same time). Without world changes, first-pass boxes stay and second-pass boxes never come.
struct MovableSpec {
  std::string id;              // swap group
  std::string pass = "first";  // first or second
  BoxSpec box;
  template <class V>
  void visit(V& v) {
    v("id", id);
    v("pass", pass);
    v("box", box);
  }
};

// A door threshold: a raised strip across a doorway from `a` to `b` (world xy), `height` above
// the floor and `width` wide, with bevelled edges; a wheel climbs it as a smooth ramp.
struct ThresholdSpec {
  std::vector<double> a = {0, 0}, b = {1, 0};  // [m] ends in world
  double height = 0.015;                       // [m] 10-20 mm is usual for door thresholds
  double width = 0.06;                         // [m] top width
  double bevel = 0.03;                         // [m] horizontal length of each ramp
  template <class V>
  void visit(V& v) {
    v("a", a);
    v("b", b);
    v("height", height);
    v("width", width);
    v("bevel", bevel);
  }
};

// A gentle floor ramp: along the segment from `a` to `b` (world xy) over `width` across it, the
// floor rises at `slope_rad` for the first half and falls back for the second half (a hump, so the
// floor outside stays at floor_z, the height the scanners' beams meet).
struct RampSpec {
  std::vector<double> a = {0, 0}, b = {1, 0};  // [m] ends in world
  double width = 2.0;                          // [m] across the segment
  double slope_rad = 0.0087;                   // [rad] 0.5 deg
  template <class V>
  void visit(V& v) {
    v("a", a);
    v("b", b);
    v("width", width);
    v("slope_rad", slope_rad);
  }
};

// The floor as the cart's wheels feel it (the simulator's floor model; the scanners still see
// the plane floor_z): square tiles whose joints step by a few mm, thresholds and ramps.
struct FloorSpec {
  double tile_size_m = 0.6;  // [m] edge of the square floor tiles (0: no tiles)
  std::vector<ThresholdSpec> thresholds;
  std::vector<RampSpec> ramps;
  template <class V>
  void visit(V& v) {
    v("tile_size_m", tile_size_m);
    v("thresholds", thresholds);
    v("ramps", ramps);
  }
};

// Elements with `layer: NAME` exist only when the simulator runs with layer NAME (the realistic
// profile uses layer "realistic"), those with `layer: "!NAME"` only without it; elements without a
// layer always. Evaluators that build the world without naming layers get every element.
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
  std::vector<MovableSpec> movables;
  FloorSpec floor;
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
    v("movables", movables);
    v("floor", floor);
  }
};

}  // namespace traverse::sim
