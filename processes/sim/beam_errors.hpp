// Per-beam errors beyond white noise (the realistic profile's beam effects):
// - surfaces that are not exact planes: a deviation along the surface normal that is fixed in the
//   world (so every pass reads the same bulge) made of a smooth part (non-planarity of plaster and
//   panels, wavelength metres) and a fine part (roughness, wavelength centimetres);
// - mixed pixels: a beam whose footprint straddles a depth jump returns a range between the two
//   surfaces, weighted by the power each part of the footprint sends back (Hebert and Krotkov,
//   "3D measurements from imaging laser radars", 1992; Tang et al. 2007 on mixed pixels of
//   phase-based scanners); how much of the footprint lies across the jump follows from where the
//   jump falls between two beams (uniform) and the footprint's size, so the probability of a mixed
//   pixel is the footprint's overlap with the jump;
// - glass and metal that answer by the angle of incidence: a specular return straight back near
//   normal incidence, more mirroring towards grazing (Fresnel reflectance, Schlick's
//   approximation, Schlick 1994).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "effects.hpp"
#include "rng.hpp"
#include "world.hpp"

namespace traverse::sim {

class SurfaceModel {
 public:
  SurfaceModel(const SurfaceEffect& effect, uint64_t seed);
  // [m] deviation of the true surface from the modelled one along `normal` (towards the sensor
  // positive: the surface is nearer) at world point p. Floor and ceiling (normal along z) use
  // their own pattern too.
  double deviation(const Eigen::Vector3d& p, const Eigen::Vector3d& normal) const;

 private:
  SurfaceEffect effect_;
  double phase_[5] = {}, skew_[2] = {};
};

// What a beam found before mixed pixels and quantisation: the true range of its surface, the
// weight of the power it returned, and the measured range (bias and noise included).
struct BeamReturn {
  float range = 0.0f;       // [m] measured, 0 = no return
  double true_range = 0.0;  // [m] to the surface it returned from (0: none)
  double power = 0.0;       // relative returned power (reflectivity x cos(incidence) / range^2)
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // [m] world, where it met the surface
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, of that surface
};

// Beam footprint: radius [m] at range r of a beam with exit diameter d0 and full divergence a.
inline double footprint_radius(double r, double exit_diameter_m, double divergence_rad) {
  return 0.5 * (exit_diameter_m + divergence_rad * r);
}

// Mixes the returns of one sweep at every depth jump: for each pair of neighbouring beams whose
// ranges differ by more than `jump_m` and each of whose points lies more than `jump_m` off the
// other's surface (not one slanted surface seen at a grazing angle), the jump is put at a uniform
// place between them and each beam whose footprint reaches across it returns the power-weighted
// mean of the two surfaces' ranges (keeping its own bias and noise). Returns the number of beams
// changed.
int mix_pixels(std::vector<BeamReturn>& beams, double angle_step_rad, double exit_diameter_m,
               double divergence_rad, double jump_m, Rng& rng);

// Probabilities that a beam reaching a non-diffuse material (p_return < 1) at incidence angle
// `incidence_rad` returns from it or mirrors off it (else it passes through).
void incidence_probabilities(const Material& m, double incidence_rad, double& p_return,
                             double& p_mirror);

}  // namespace traverse::sim
