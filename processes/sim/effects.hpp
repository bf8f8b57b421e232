// What makes a simulated run as hard as the field: the realistic profile's effects, each with its
// own switch and magnitudes (configs/sim.yaml, `effects:`, restates these defaults with the
// source of each figure). The ideal profile (`Effects::ideal()`) switches every one off: the
// cart drives a plane floor, stops and turns on the spot, the sensors share the true clock and
// the rig file's extrinsics, beams see a static world of exact planes with white noise only.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace traverse::sim {

// The cart on a real floor: tiles whose joints step (lippage), door thresholds and ramps of the
// world file lift its wheels, so it pitches and rolls (floor.hpp).
struct FloorEffect {
  bool enabled = true;
  double tile_step_sigma_m = 0.0012;  // [m] 1 sigma height offset of a tile against the mean
  double tile_step_max_m = 0.003;     // [m] offsets are clipped here (joints step 1-3 mm)
  double joint_ramp_m = 0.015;        // [m] a wheel climbs a joint's step over this length
  double wheelbase_m = 0.6;           // [m] front to rear wheel axles
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("tile_step_sigma_m", tile_step_sigma_m);
    v("tile_step_max_m", tile_step_max_m);
    v("joint_ramp_m", joint_ramp_m);
    v("wheelbase_m", wheelbase_m);
  }
};

// A cart pushed by a person (pushed_path.hpp): corners are driven as arcs while moving, the speed
// wanders about the route's cruise speed and slows in turns, the path weaves a little; only
// reversals are turned on the spot.
struct MotionEffect {
  bool enabled = true;
  double corner_radius_m = 0.8;     // [m] largest arc radius through a corner
  double lateral_accel_mps2 = 0.3;  // [m/s^2] speed in an arc is at most sqrt(a r)
  double speed_variation = 0.12;    // 1 sigma of the relative speed change about cruise
  double speed_wavelength_m = 6.0;  // [m] travel over which the speed wanders
  double weave_m = 0.03;            // [m] 1 sigma lateral weave about the straight line
  double weave_wavelength_m = 8.0;  // [m]
  double spin_turn_min_rad = 2.6;   // [rad] sharper turns (reversals) are turned on the spot
  // The cart is set down at the route's start by eye, turned from its first leg by a yaw of
  // magnitude uniform in [min, max] and random sign (the first scan, which fixes the map's frame,
  // is not square to the walls), and rolls back onto the line over its first start_settle_m.
  double start_yaw_min_rad = 0.0087;  // [rad] 0.5 deg
  double start_yaw_max_rad = 0.035;   // [rad] 2 deg
  double start_settle_m = 2.0;        // [m]
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("corner_radius_m", corner_radius_m);
    v("lateral_accel_mps2", lateral_accel_mps2);
    v("speed_variation", speed_variation);
    v("speed_wavelength_m", speed_wavelength_m);
    v("weave_m", weave_m);
    v("weave_wavelength_m", weave_wavelength_m);
    v("spin_turn_min_rad", spin_turn_min_rad);
    v("start_yaw_min_rad", start_yaw_min_rad);
    v("start_yaw_max_rad", start_yaw_max_rad);
    v("start_settle_m", start_settle_m);
  }
};

// Every sensor stamps with its own clock: stamp = true time + offset + drift x elapsed + jitter.
// Drawn per run and sensor; nothing in the messages tells the true values (clocks.hpp).
struct ClockEffect {
  bool enabled = true;
  double offset_max_s = 0.005;  // [s] offset uniform in +- this
  double drift_min_ppm = 10.0;  // [ppm] drift magnitude uniform in [min, max], random sign
  double drift_max_ppm = 50.0;
  double jitter_s = 0.001;  // [s] 1 sigma of each message's stamp jitter
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("offset_max_s", offset_max_s);
    v("drift_min_ppm", drift_min_ppm);
    v("drift_max_ppm", drift_max_ppm);
    v("jitter_s", jitter_s);
  }
};

// The true extrinsics differ from configs/rig.yaml by a per-run error (calibration.hpp).
struct CalibrationEffect {
  bool enabled = true;
  double yaw_min_rad = 0.00175;      // [rad] yaw error magnitude uniform in [min, max] (0.1 deg)
  double yaw_max_rad = 0.00524;      // [rad] (0.3 deg), random sign
  double tilt_sigma_rad = 0.00087;   // [rad] 1 sigma roll and pitch error (0.05 deg)
  double lever_arm_sigma_m = 0.005;  // [m] 1 sigma per axis of the origin error
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("yaw_min_rad", yaw_min_rad);
    v("yaw_max_rad", yaw_max_rad);
    v("tilt_sigma_rad", tilt_sigma_rad);
    v("lever_arm_sigma_m", lever_arm_sigma_m);
  }
};

// Surfaces are not exact planes: a smooth deviation along each wall's normal (non-planarity of
// plaster and panels) plus fine roughness, fixed in the world (the same spot reads the same on
// every pass), drawn from the seed (beam_errors.hpp).
struct SurfaceEffect {
  bool enabled = true;
  double non_planarity_m = 0.004;           // [m] 1 sigma of the smooth deviation
  double non_planarity_wavelength_m = 2.5;  // [m]
  double roughness_m = 0.001;               // [m] 1 sigma of the fine part
  double roughness_wavelength_m = 0.03;     // [m]
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("non_planarity_m", non_planarity_m);
    v("non_planarity_wavelength_m", non_planarity_wavelength_m);
    v("roughness_m", roughness_m);
    v("roughness_wavelength_m", roughness_wavelength_m);
  }
};

// Per-beam errors beyond white noise; the magnitudes of the scanner-specific ones are the rig's
// (rig.hpp RangeModel: angle_jitter_rad, dark_bias_m, range_resolution_m, beam footprint).
struct BeamEffects {
  bool mixed_pixels = true;         // a footprint across a depth jump returns a range in between
  bool angle_jitter = true;         // each beam's true angle scatters about its nominal one
  bool material_bias = true;        // dark surfaces read longer (range walk)
  bool incidence_materials = true;  // glass and metal answer by the angle of incidence
  bool quantisation = true;         // ranges as the scanner outputs them (range_resolution_m)
  SurfaceEffect surface;
  template <class V>
  void visit(V& v) {
    v("mixed_pixels", mixed_pixels);
    v("angle_jitter", angle_jitter);
    v("material_bias", material_bias);
    v("incidence_materials", incidence_materials);
    v("quantisation", quantisation);
    v("surface", surface);
  }
};

// People walking through the scans on two legs (people.hpp).
struct PeopleEffect {
  bool enabled = true;
  double per_minute = 2.0;     // mean number of people appearing near the cart per minute
  double speed_min_mps = 1.0;  // [m/s] walking speed uniform in [min, max]
  double speed_max_mps = 1.5;
  double walk_min_s = 4.0;  // [s] time a person is there, uniform in [min, max]
  double walk_max_s = 12.0;
  double leg_radius_m = 0.06;     // [m]
  double hip_half_width_m = 0.1;  // [m] leg axis from the walking line
  double step_length_m = 0.7;     // [m] one step; a leg swings +- a quarter stride
  double body_radius_m = 0.18;    // [m] torso from 0.85 m to 1.75 m
  double reflectivity = 0.25;     // clothing
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("per_minute", per_minute);
    v("speed_min_mps", speed_min_mps);
    v("speed_max_mps", speed_max_mps);
    v("walk_min_s", walk_min_s);
    v("walk_max_s", walk_max_s);
    v("leg_radius_m", leg_radius_m);
    v("hip_half_width_m", hip_half_width_m);
    v("step_length_m", step_length_m);
    v("body_radius_m", body_radius_m);
    v("reflectivity", reflectivity);
  }
};

// Doors and chairs of the world file's `movables` differ between the first and second pass.
struct WorldChangeEffect {
  bool enabled = true;
  double visit_radius_m = 8.0;  // [m] the cart "visits" a movable while this close to it
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("visit_radius_m", visit_radius_m);
  }
};

// Wheel encoders on the two rear wheels, published as odometry_t on ODOMETRY (odometry.hpp).
// Off by default: the FARO cart of seed 000 has none.
struct WheelEncoderEffect {
  bool enabled = false;
  double rate_hz = 50.0;              // [Hz]
  int ticks_per_rev = 1024;           // encoder resolution
  double wheel_radius_m = 0.1;        // [m] nominal radius the odometry integrates with
  double radius_error_sigma = 0.003;  // 1 sigma relative error of each wheel's true radius
  double track_error_sigma = 0.01;    // 1 sigma relative error of the true wheel track
  double slip_sigma = 0.01;           // 1 sigma relative slip of each wheel per sample
  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("rate_hz", rate_hz);
    v("ticks_per_rev", ticks_per_rev);
    v("wheel_radius_m", wheel_radius_m);
    v("radius_error_sigma", radius_error_sigma);
    v("track_error_sigma", track_error_sigma);
    v("slip_sigma", slip_sigma);
  }
};

struct Effects {
  std::vector<std::string> world_layers = {"realistic"};  // world file layers to build
  FloorEffect floor;
  MotionEffect motion;
  ClockEffect clocks;
  CalibrationEffect calibration;
  BeamEffects beams;
  PeopleEffect people;
  WorldChangeEffect world_changes;
  WheelEncoderEffect wheel_encoders;
  template <class V>
  void visit(V& v) {
    v("world_layers", world_layers);
    v("floor", floor);
    v("motion", motion);
    v("clocks", clocks);
    v("calibration", calibration);
    v("beams", beams);
    v("people", people);
    v("world_changes", world_changes);
    v("wheel_encoders", wheel_encoders);
  }

  // Every effect off and no layer: the simulator as it was before the realistic profile (a given
  // seed gives the same log). Wheel encoders keep their setting: they add a stream, not an error.
  Effects ideal() const;
  // Anything that needs the cart's 3D pose (floor or calibration tilt).
  bool three_d() const { return floor.enabled || calibration.enabled; }
};

std::optional<std::string> validate(const Effects& e);

}  // namespace traverse::sim
