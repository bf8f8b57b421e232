#include "effects.hpp"

#include "config.hpp"

namespace traverse::sim {

Effects Effects::ideal() const {
  Effects e = *this;
  e.world_layers.clear();
  e.floor.enabled = false;
  e.motion.enabled = false;
  e.clocks.enabled = false;
  e.calibration.enabled = false;
  e.beams.mixed_pixels = false;
  e.beams.angle_jitter = false;
  e.beams.material_bias = false;
  e.beams.incidence_materials = false;
  e.beams.quantisation = false;
  e.beams.surface.enabled = false;
  e.people.enabled = false;
  e.world_changes.enabled = false;
  return e;
}

namespace {

std::optional<std::string> check_floor(const FloorEffect& f) {
  ConfigCheck c;
  c.in_range("tile_step_sigma_m", f.tile_step_sigma_m, 0.0, 0.01);
  c.in_range("tile_step_max_m", f.tile_step_max_m, 0.0, 0.02);
  c.in_range("joint_ramp_m", f.joint_ramp_m, 0.001, 0.2);
  c.in_range("wheelbase_m", f.wheelbase_m, 0.1, 3.0);
  return c.problem();
}

std::optional<std::string> check_motion(const MotionEffect& m) {
  ConfigCheck c;
  c.in_range("corner_radius_m", m.corner_radius_m, 0.05, 5.0);
  c.in_range("lateral_accel_mps2", m.lateral_accel_mps2, 0.01, 5.0);
  c.in_range("speed_variation", m.speed_variation, 0.0, 0.5);
  c.in_range("speed_wavelength_m", m.speed_wavelength_m, 0.5, 100.0);
  c.in_range("weave_m", m.weave_m, 0.0, 0.2);
  c.in_range("weave_wavelength_m", m.weave_wavelength_m, 1.0, 100.0);
  c.in_range("spin_turn_min_rad", m.spin_turn_min_rad, 0.5, 3.1416);
  c.in_range("start_yaw_min_rad", m.start_yaw_min_rad, 0.0, 0.2);
  c.in_range("start_yaw_max_rad", m.start_yaw_max_rad, 0.0, 0.2);
  c.require(m.start_yaw_max_rad >= m.start_yaw_min_rad, "start_yaw_max_rad",
            "must be >= start_yaw_min_rad");
  c.in_range("start_settle_m", m.start_settle_m, 0.1, 20.0);
  return c.problem();
}

std::optional<std::string> check_clocks(const ClockEffect& k) {
  ConfigCheck c;
  c.in_range("offset_max_s", k.offset_max_s, 0.0, 1.0);
  c.in_range("drift_min_ppm", k.drift_min_ppm, 0.0, 1000.0);
  c.in_range("drift_max_ppm", k.drift_max_ppm, 0.0, 1000.0);
  c.require(k.drift_max_ppm >= k.drift_min_ppm, "drift_max_ppm", "must be >= drift_min_ppm");
  c.in_range("jitter_s", k.jitter_s, 0.0, 0.1);
  return c.problem();
}

std::optional<std::string> check_calibration(const CalibrationEffect& k) {
  ConfigCheck c;
  c.in_range("yaw_min_rad", k.yaw_min_rad, 0.0, 0.1);
  c.in_range("yaw_max_rad", k.yaw_max_rad, 0.0, 0.1);
  c.require(k.yaw_max_rad >= k.yaw_min_rad, "yaw_max_rad", "must be >= yaw_min_rad");
  c.in_range("tilt_sigma_rad", k.tilt_sigma_rad, 0.0, 0.05);
  c.in_range("lever_arm_sigma_m", k.lever_arm_sigma_m, 0.0, 0.1);
  return c.problem();
}

std::optional<std::string> check_surface(const SurfaceEffect& s) {
  ConfigCheck c;
  c.in_range("non_planarity_m", s.non_planarity_m, 0.0, 0.05);
  c.in_range("non_planarity_wavelength_m", s.non_planarity_wavelength_m, 0.1, 50.0);
  c.in_range("roughness_m", s.roughness_m, 0.0, 0.01);
  c.in_range("roughness_wavelength_m", s.roughness_wavelength_m, 0.001, 1.0);
  return c.problem();
}

std::optional<std::string> check_people(const PeopleEffect& p) {
  ConfigCheck c;
  c.in_range("per_minute", p.per_minute, 0.0, 60.0);
  c.in_range("speed_min_mps", p.speed_min_mps, 0.1, 3.0);
  c.in_range("speed_max_mps", p.speed_max_mps, 0.1, 3.0);
  c.require(p.speed_max_mps >= p.speed_min_mps, "speed_max_mps", "must be >= speed_min_mps");
  c.in_range("walk_min_s", p.walk_min_s, 0.5, 120.0);
  c.in_range("walk_max_s", p.walk_max_s, 0.5, 120.0);
  c.require(p.walk_max_s >= p.walk_min_s, "walk_max_s", "must be >= walk_min_s");
  c.in_range("leg_radius_m", p.leg_radius_m, 0.02, 0.2);
  c.in_range("hip_half_width_m", p.hip_half_width_m, 0.0, 0.3);
  c.in_range("step_length_m", p.step_length_m, 0.1, 1.5);
  c.in_range("body_radius_m", p.body_radius_m, 0.05, 0.5);
  c.in_range("reflectivity", p.reflectivity, 0.0, 1.0);
  return c.problem();
}

std::optional<std::string> check_encoders(const WheelEncoderEffect& w) {
  ConfigCheck c;
  c.in_range("rate_hz", w.rate_hz, 1.0, 1000.0);
  c.in_range("ticks_per_rev", w.ticks_per_rev, 1, 1 << 24);
  c.in_range("wheel_radius_m", w.wheel_radius_m, 0.01, 1.0);
  c.in_range("radius_error_sigma", w.radius_error_sigma, 0.0, 0.1);
  c.in_range("track_error_sigma", w.track_error_sigma, 0.0, 0.1);
  c.in_range("slip_sigma", w.slip_sigma, 0.0, 0.5);
  return c.problem();
}

}  // namespace

std::optional<std::string> validate(const Effects& e) {
  ConfigCheck c;
  for (const auto& layer : e.world_layers) c.not_empty("world_layers", layer);
  c.nested("floor", check_floor(e.floor));
  c.nested("motion", check_motion(e.motion));
  c.nested("clocks", check_clocks(e.clocks));
  c.nested("calibration", check_calibration(e.calibration));
  c.nested("beams.surface", check_surface(e.beams.surface));
  c.nested("people", check_people(e.people));
  c.in_range("world_changes.visit_radius_m", e.world_changes.visit_radius_m, 0.5, 100.0);
  c.nested("wheel_encoders", check_encoders(e.wheel_encoders));
  return c.problem();
}

}  // namespace traverse::sim
