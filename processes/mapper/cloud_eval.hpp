// Accuracy of a point cloud against the simulator's true world, in the terms of the seeds:
//  - distance from each point to the nearest true surface: mode, mean, RMSE, 95th percentile
//    (seed 004, Table 1);
//  - pillar centres fitted from the cloud against the true centres: n, mean, SD, RMSE, min, max of
//    the planar error (seed 000, Table 3). Each pillar's points are taken from an annulus around
//    the true centre (the paper picked them interactively) and a circle of the pillar's known
//    radius is fitted by Gauss-Newton, dropping points far from the current circle (walls
//    that a half-embedded pillar stands in);
//  - corridor lengths between two end walls (seed 000, section 3): each end wall's position is the
//    median coordinate of the cloud points near it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mapper.hpp"
#include "se2.hpp"
#include "world.hpp"
#include "world_spec.hpp"

namespace traverse::mapper {

// An end wall of a corridor: the plane x = at (axis "x") or y = at (axis "y"), seen through one or
// more boxes. Several intervals let one end be taken where the scanner actually saw that plane:
// the profile scanner reaches 6 m, and a corridor's own end may never come that close while the
// same plane, continued into a neighbouring room, does.
struct WallProbe {
  std::string axis = "x";
  double at = 0.0;  // [m] true position of the plane
  // [m] intervals [lo, hi] of the other horizontal coordinate where the plane is probed
  std::vector<std::vector<double>> across = {{0, 1}};
  template <class V>
  void visit(V& v) {
    v("axis", axis);
    v("at", at);
    v("across", across);
  }
};

struct CorridorSpec {
  std::string name;
  WallProbe end_a, end_b;
  template <class V>
  void visit(V& v) {
    v("name", name);
    v("end_a", end_a);
    v("end_b", end_b);
  }
};

struct CloudEvalConfig {
  double max_search_m = 0.5;        // [m] distances are capped here (gross outliers)
  double histogram_bin_m = 0.0005;  // [m] bin of the distance histogram (mode)
  double pillar_band_m = 0.05;      // [m] points within this of the true pillar surface are used
  double pillar_trim_m = 0.015;     // [m] points farther from the fitted circle are dropped
  int pillar_min_points = 50;
  double z_min_m = 0.3, z_max_m = 2.5;  // [m] height band of pillar and wall points
  double wall_band_m = 0.1;             // [m] points within this of an end wall's true plane
  std::vector<CorridorSpec> corridors;
  template <class V>
  void visit(V& v) {
    v("max_search_m", max_search_m);
    v("histogram_bin_m", histogram_bin_m);
    v("pillar_band_m", pillar_band_m);
    v("pillar_trim_m", pillar_trim_m);
    v("pillar_min_points", pillar_min_points);
    v("z_min_m", z_min_m);
    v("z_max_m", z_max_m);
    v("wall_band_m", wall_band_m);
    v("corridors", corridors);
  }
};

struct Stats {
  int n = 0;
  double mean = 0, sd = 0, rmse = 0, min = 0, max = 0, p95 = 0, mode = 0;
};

struct PillarResult {
  std::string id;
  int points = 0;
  std::optional<double> error_m;  // planar centre error; nullopt when too few points
};

struct CorridorResult {
  std::string name;
  std::optional<double> length_m;  // measured in the cloud
  double true_length_m = 0;
  int points_a = 0, points_b = 0;  // cloud points near each end wall
};

// The first value out of range, named by its key path; nullopt when the config is usable.
std::optional<std::string> validate(const WallProbe& probe);
std::optional<std::string> validate(const CloudEvalConfig& config);

struct CloudEvalResult {
  Stats surface;  // point-to-surface distances [m]
  std::vector<PillarResult> pillars;
  Stats pillar;  // over pillars with a fit [m]
  std::vector<CorridorResult> corridors;
};

// Moves every point by a planar transform T_world_map (the cloud was built in the map frame).
void transform_cloud(std::vector<CloudPoint>& cloud, const Pose2& T_world_map);

// Statistics of a sample (mode from a histogram with `bin` wide bins, if bin > 0).
Stats describe(std::vector<double> values, double bin);

// Fits a circle of known `radius` to 2D points starting from `start`; nullopt if it fails.
std::optional<Eigen::Vector2d> fit_circle(const std::vector<Eigen::Vector2d>& pts,
                                          const Eigen::Vector2d& start, double radius,
                                          double trim_m);

// Surface distances use every `stride`-th point (all when 1); pillars and corridors all points.
CloudEvalResult evaluate_cloud(const std::vector<CloudPoint>& cloud, const sim::World& world,
                               const sim::WorldSpec& spec, const CloudEvalConfig& config,
                               std::size_t stride = 1);

}  // namespace traverse::mapper
