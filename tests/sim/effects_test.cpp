// The realistic profile's sensor and world effects, each switched on alone against a scene whose
// answer is known: mixed pixels only at depth jumps, a clock offset in the stamps, a calibration
// error in the scan, a person who appears and leaves, a door that closes between passes, walls
// that are not planes, dark surfaces that read long, glass by incidence, angle jitter, ranges in
// the scanner's output steps.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sensors.hpp"
#include "simulator.hpp"

namespace traverse::sim {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// A wall across the x axis at x = 10, materials for the tests, and whatever a test adds.
WorldSpec scene(double wall_reflectivity = 0.5) {
  WorldSpec w;
  w.name = "scene";
  w.materials = {{"wall", wall_reflectivity, 1.0, 0.0},
                 {"floor", 0.3, 1.0, 0.0},
                 {"glass", 0.08, 0.08, 0.07},
                 {"dark", 0.1, 1.0, 0.0},
                 {"bright", 0.9, 1.0, 0.0}};
  WallSpec wall;
  wall.points = {{10, -60}, {10, 60}};
  wall.z = {0.0, 3.0};
  w.walls = {wall};
  return w;
}

// The cart standing at the origin facing +x for 60 s.
RouteSpec standing() {
  RouteSpec r;
  r.world = "scene";
  r.waypoints = {{0, 0}, {0.5, 0}};
  r.start_pause_s = 60.0;
  return r;
}

// A scanner model without random errors (noise, offset, dropout), to see one effect alone.
ScannerModel quiet(ScannerModel m) {
  m.range.noise_10m_bright_m = m.range.noise_25m_bright_m = 1e-9;
  m.range.noise_10m_dark_m = m.range.noise_25m_dark_m = 1e-9;
  m.range.ranging_error_m = 0.0;
  m.range.random_dropout = 0.0;
  return m;
}

struct Scene {
  explicit Scene(const WorldSpec& spec, const WorldOptions& options = {})
      : world(spec, 0.5, options),
        rng(1),
        trajectory(standing(), PlatformConfig{}, rng, Effects{}.ideal()) {}
  ScannerSim scanner(const ScannerModel& m, const ScanExtras& extras = {},
                     const Extrinsic& e = {0, 0, 0.5, 0, 0, 0}) {
    return ScannerSim(m, e, "laser", world, trajectory, clock, Rng(2), extras);
  }
  World world;
  Rng rng;
  Trajectory trajectory;
  Clock clock{0};
};

ScanExtras only(void (*set)(BeamEffects&)) {
  ScanExtras x;
  set(x.beams);
  return x;
}

TEST(MixedPixels, OnlyAtDepthJumps) {
  WorldSpec spec = scene();
  BoxSpec box;  // a 1 m wide box 5 m ahead: depth jumps of 5 m at its two edges
  box.x = 5.0;
  box.size = {0.2, 1.0, 3.0};
  box.material = "wall";
  spec.boxes = {box};
  Scene s(spec);
  const ScannerModel m = quiet(sick_lms111());
  ScannerSim plain = s.scanner(m);
  ScannerSim mixing = s.scanner(m, only([](BeamEffects& b) { b.mixed_pixels = true; }));
  const ScanData ref = plain.sweep(0);
  std::vector<int> edges;  // beams next to a jump
  for (int i = 0; i + 1 < m.points; ++i)
    if (ref.ranges[i] > 0 && ref.ranges[i + 1] > 0 &&
        std::abs(ref.ranges[i] - ref.ranges[i + 1]) > 1.0)
      edges.push_back(i);
  ASSERT_EQ(edges.size(), 2u);
  int between = 0;
  for (int k = 0; k < 40; ++k) {
    const ScanData scan = mixing.sweep(k);
    for (int i = 0; i < m.points; ++i) {
      const float r = scan.ranges[i];
      if (std::abs(r - ref.ranges[i]) < 1e-3f) continue;
      // Every changed beam lies between the two surfaces, next to a jump.
      EXPECT_GT(r, 4.9f);
      EXPECT_LT(r, 10.2f);
      bool near_edge = false;
      for (int e : edges) near_edge |= i >= e - 1 && i <= e + 2;
      EXPECT_TRUE(near_edge) << "beam " << i;
      between += r > 5.1f && r < 9.9f;
    }
  }
  EXPECT_GT(between, 10);  // the footprint (15 mrad) is 1.7 beam steps: most sweeps mix
  for (float r : plain.sweep(1).ranges)
    EXPECT_TRUE(r == 0.0f || std::abs(r - 5.0f) < 0.2f || r > 9.9f);  // off: never between
}

TEST(Clocks, AnOffsetShowsInTheStampsAndNotInTheRanges) {
  Scene s(scene());
  const ScannerModel m = quiet(focus3d_120s());
  ScanExtras x;
  x.clock.enabled = true;
  x.clock.offset_s = 0.004;
  x.clock.drift = 30e-6;
  ScannerSim plain = s.scanner(m), clocked = s.scanner(m, x);
  for (int64_t k : {0, 100, 1000}) {
    const ScanData a = plain.sweep(k), b = clocked.sweep(k);
    const double t = 1e-6 * static_cast<double>(a.utime_first);
    EXPECT_EQ(b.utime_first - a.utime_first, std::llround(1e6 * (0.004 + 30e-6 * t)));
    EXPECT_NEAR(static_cast<double>(b.utime_last - b.utime_first),
                (a.utime_last - a.utime_first) * (1.0 + 30e-6), 1.0);
    EXPECT_EQ(a.ranges, b.ranges);  // measured at the true time all the same
  }
  // Drawn per run within the configured bounds; jitter bounded at 2 sigma.
  ClockEffect e;
  for (uint64_t seed = 1; seed < 50; ++seed) {
    const SensorClock c = SensorClock::draw(e, seed, 5);
    EXPECT_LE(std::abs(c.offset_s), 0.005);
    EXPECT_GE(std::abs(c.drift), 10e-6);
    EXPECT_LE(std::abs(c.drift), 50e-6);
    const int64_t jittered =
        c.stamp(0, 0.0, static_cast<int64_t>(seed)) - std::llround(1e6 * c.offset_s);
    EXPECT_LE(std::abs(jittered), 2001);
  }
}

TEST(Calibration, AYawErrorTurnsTheWallInTheScan) {
  Scene s(scene());
  const ScannerModel m = quiet(focus3d_120s());
  CalibrationEffect c;
  c.tilt_sigma_rad = 0.0;
  c.lever_arm_sigma_m = 0.0;
  Rng rng(4);
  const Extrinsic nominal{0, 0, 0.5, 0, 0, 0};
  const Extrinsic truth = perturb_extrinsic(nominal, c, rng);
  const double err = truth.yaw - nominal.yaw;
  EXPECT_GE(std::abs(err), 0.1 * kRadPerDeg);
  EXPECT_LE(std::abs(err), 0.3 * kRadPerDeg);
  // The nearest point of the wall (its normal) appears at -err in the scan, not at 0.
  auto normal_angle = [&](const Extrinsic& e) {
    ScannerSim sc = s.scanner(m, {}, e);
    const ScanData scan = sc.sweep(0);
    int best = 0;
    for (int i = 0; i < m.points; ++i)
      if (scan.ranges[i] > 0 && (scan.ranges[best] <= 0 || scan.ranges[i] < scan.ranges[best]))
        best = i;
    return scan.angle_first + best * scan.angle_step;
  };
  EXPECT_NEAR(normal_angle(nominal), 0.0, m.angle_step_rad);
  EXPECT_NEAR(normal_angle(truth), -err, 1.5 * m.angle_step_rad);
}

TEST(People, APersonAppearsWalksOnTwoLegsAndLeaves) {
  Scene s(scene());
  Person p;  // across the beams 4 m ahead, from t = 20 s to 24 s
  p.t0 = 20.0;
  p.t1 = 24.0;
  p.start = {4.0, -2.4};
  p.dir = {0.0, 1.0};
  p.speed = 1.2;
  const People people(PeopleEffect{}, {p});
  ScanExtras x;
  x.people = &people;
  ScannerSim sc = s.scanner(quiet(focus3d_120s()), x);
  auto near_hits = [&](double t, int& clusters) {
    const ScanData scan = sc.sweep(std::llround(t * 47.7));
    int hits = 0;
    clusters = 0;
    bool in = false;
    for (float r : scan.ranges) {
      const bool on_person = r > 0.0f && r < 5.0f;
      hits += on_person;
      clusters += on_person && !in;
      in = on_person;
    }
    return hits;
  };
  int clusters = 0;
  EXPECT_EQ(near_hits(19.0, clusters), 0);
  int most_clusters = 0, during = 0;
  for (double t = 21.5; t < 22.5; t += 0.05) {
    during += near_hits(t, clusters);
    most_clusters = std::max(most_clusters, clusters);
  }
  EXPECT_GT(during, 100);
  EXPECT_EQ(most_clusters, 2);  // two legs, apart in mid stride
  EXPECT_EQ(near_hits(25.0, clusters), 0);
}

TEST(WorldChanges, ADoorClosesBetweenTheFirstAndSecondPass) {
  WorldSpec spec = scene();
  MovableSpec open_leaf, closed_leaf;
  open_leaf.id = closed_leaf.id = "door";
  open_leaf.box = {6.0, 1.0, 0.0, {0.04, 0.9, 2.0}, 0.0, "wall", ""};
  closed_leaf.pass = "second";
  closed_leaf.box = {6.0, 0.0, 0.0, {0.04, 0.9, 2.0}, 0.0, "wall", ""};
  spec.movables = {open_leaf, closed_leaf};
  WorldOptions opt;
  opt.layers = std::vector<std::string>{};
  opt.swap_times = std::map<std::string, double>{{"door", 50.0}};
  const World world(spec, 0.5, opt);
  const Eigen::Vector3d o(0, 0, 1.0), d(1, 0, 0);
  EXPECT_NEAR(world.raycast(o, d, 40.0, 1e-6, 10.0)->t, 10.0, 1e-9);  // open: the wall behind
  EXPECT_NEAR(world.raycast(o, d, 40.0, 1e-6, 60.0)->t, 5.98, 1e-9);  // closed
  // Without world changes the first pass stays; an evaluator's world has both.
  opt.swap_times.reset();
  EXPECT_NEAR(World(spec, 0.5, opt).raycast(o, d, 40.0, 1e-6, 60.0)->t, 10.0, 1e-9);
  EXPECT_NEAR(World(spec).raycast(o, d, 40.0, 1e-6, 0.0)->t, 5.98, 1e-9);
  // The swap falls between the cart's two visits: out past it and back.
  RouteSpec r;
  r.world = "scene";
  r.waypoints = {{0, 0}, {30, 0}, {0, 0}};
  Rng rng(1);
  const Trajectory t(r, PlatformConfig{}, rng, Effects{}.ideal());
  const double swap = movable_swap_times(spec, t, 8.0).at("door");
  EXPECT_GT((t.nominal_pose(swap).translation() - Eigen::Vector2d(6, 0.5)).norm(), 8.0);
  EXPECT_GT(swap, 20.0);
  EXPECT_LT(swap, t.duration_s() - 20.0);
}

TEST(Surfaces, WallsAreNotPlanesButTheSameOnEveryPass) {
  SurfaceEffect e;
  const SurfaceModel surface(e, 3);
  const Eigen::Vector3d n(-1, 0, 0);
  double sum2 = 0.0, peak = 0.0;
  int count = 0;
  for (double y = -20; y < 20; y += 0.05)
    for (double z = 0.2; z < 2.8; z += 0.2) {
      const double dev = surface.deviation({10, y, z}, n);
      EXPECT_EQ(dev, surface.deviation({10, y, z}, n));
      sum2 += dev * dev;
      peak = std::max(peak, std::abs(dev));
      ++count;
    }
  const double rms = std::sqrt(sum2 / count);
  EXPECT_GT(rms, 0.7 * std::hypot(e.non_planarity_m, e.roughness_m));
  EXPECT_LT(rms, 1.3 * std::hypot(e.non_planarity_m, e.roughness_m));
  EXPECT_GT(peak, 0.003);
  EXPECT_LT(peak, 0.015);
}

TEST(MaterialBias, DarkSurfacesReadLonger) {
  auto range_on = [](double reflectivity, bool bias) {
    Scene s(scene(reflectivity));
    ScanExtras x;
    x.beams.material_bias = bias;
    ScannerSim sc = s.scanner(quiet(sick_lms111()), x);
    return sc.sweep(0).ranges[270];  // straight ahead
  };
  EXPECT_NEAR(range_on(0.1, false), range_on(0.9, false), 1e-4);
  // 15 mm at 10 % against 90 % (the rig's dark_bias_m), less the level's fall with range.
  const double walk = range_on(0.1, true) - range_on(0.9, true);
  EXPECT_GT(walk, 0.012);
  EXPECT_LT(walk, 0.0155);
}

TEST(IncidenceMaterials, GlassReturnsHeadOnAndMirrorsAtGrazingAngles) {
  const Material glass{"glass", 0.08, 0.08, 0.07};
  double p_return, p_mirror;
  incidence_probabilities(glass, 0.0, p_return, p_mirror);
  EXPECT_NEAR(p_return, 1.0, 1e-12);  // the pane reflects straight back
  incidence_probabilities(glass, 30 * kRadPerDeg, p_return, p_mirror);
  EXPECT_LT(p_return, 0.08);
  EXPECT_LT(p_mirror, 0.1);  // most beams pass
  incidence_probabilities(glass, 85 * kRadPerDeg, p_return, p_mirror);
  EXPECT_GT(p_mirror, 0.5);  // Fresnel: grazing beams mirror
  const Material steel{"metal", 0.9, 0.7, 0.3};
  incidence_probabilities(steel, 60 * kRadPerDeg, p_return, p_mirror);
  EXPECT_NEAR(p_return + p_mirror, 1.0, 1e-12);  // steel never lets a beam through
  EXPECT_GT(p_mirror, 0.5);
}

TEST(AngleJitter, ScattersPointsOffAWallAsTheAngleDoes) {
  Scene s(scene());
  ScannerModel m = quiet(focus3d_120s());
  m.range.angle_jitter_rad = 1e-3;
  ScanExtras x;
  x.beams.angle_jitter = true;
  ScannerSim plain = s.scanner(m), jittered = s.scanner(m, x);
  const ScanData a = plain.sweep(0), b = jittered.sweep(0);
  // A beam at angle a off the wall's normal lands tan(a) x 10 m x jitter off the wall.
  double sum2 = 0.0, expected2 = 0.0;
  int n = 0;
  for (int i = 0; i < m.points; ++i) {
    const double ang = a.angle_first + i * a.angle_step;
    if (std::abs(ang) < 20 * kRadPerDeg || std::abs(ang) > 40 * kRadPerDeg || b.ranges[i] <= 0) continue;
    const double off = b.ranges[i] * std::cos(ang) - a.ranges[i] * std::cos(ang);
    sum2 += off * off;
    expected2 += std::pow(10.0 * std::tan(ang) * 1e-3, 2);
    ++n;
  }
  ASSERT_GT(n, 1000);
  EXPECT_NEAR(std::sqrt(sum2 / n), std::sqrt(expected2 / n), 0.15 * std::sqrt(expected2 / n));
}

TEST(Quantisation, RangesComeInTheScannersOutputSteps) {
  Scene s(scene());
  ScanExtras x;
  x.beams.quantisation = true;
  ScannerSim sc = s.scanner(sick_lms200(181, 1.0), x);
  int valid = 0;
  for (float r : sc.sweep(0).ranges) {
    if (r <= 0.0f) continue;
    ++valid;
    EXPECT_NEAR(r * 100.0, std::round(r * 100.0), 1e-3);  // centimetres
  }
  EXPECT_GT(valid, 100);
}

}  // namespace
}  // namespace traverse::sim
