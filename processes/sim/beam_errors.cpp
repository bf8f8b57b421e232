#include "beam_errors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace traverse::sim {

SurfaceModel::SurfaceModel(const SurfaceEffect& effect, uint64_t seed) : effect_(effect) {
  Rng rng(seed, 0x5EEDF00DULL);
  for (double& p : phase_) p = rng.uniform(0.0, 2.0 * std::numbers::pi);
  for (double& s : skew_) s = rng.uniform(0.5, 1.5);
}

double SurfaceModel::deviation(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
  // Coordinates on the surface: (u, w) = (along a horizontal tangent, height) for walls, (x, y)
  // for floors and ceilings; the surface's own offset along its normal shifts the phases, so
  // parallel walls bulge differently.
  double u, w, off;
  if (std::abs(n.z()) > 0.7) {
    u = p.x();
    w = p.y();
    off = p.z();
  } else {
    u = -n.y() * p.x() + n.x() * p.y();
    w = p.z();
    off = n.x() * p.x() + n.y() * p.y();
  }
  const double two_pi = 2.0 * std::numbers::pi;
  const double k = two_pi / effect_.non_planarity_wavelength_m;
  const double kr = two_pi / effect_.roughness_wavelength_m;
  // Each part has unit variance: two sinusoids (1/2 each), or twice a product of two (1/4).
  const double smooth = std::sin(k * u + phase_[0] + 7.31 * off) +
                        std::sin(k * (skew_[0] * 0.61 * u + 0.8 * w) + phase_[1] + 3.17 * off);
  const double fine = 2.0 * std::sin(kr * u + phase_[2] + 11.3 * off) *
                      std::sin(kr * skew_[1] * w + phase_[3] + phase_[4]);
  return effect_.non_planarity_m * smooth + effect_.roughness_m * fine;
}

namespace {

// Area fraction of a unit disc beyond a chord at distance x (0..1) from its centre.
double disc_fraction_beyond(double x) {
  if (x >= 1.0) return 0.0;
  if (x <= -1.0) return 1.0;
  return (std::acos(x) - x * std::sqrt(1.0 - x * x)) / std::numbers::pi;
}

}  // namespace

int mix_pixels(std::vector<BeamReturn>& beams, double angle_step_rad, double exit_diameter_m,
               double divergence_rad, double jump_m, Rng& rng) {
  const int n = static_cast<int>(beams.size());
  const double step = std::abs(angle_step_rad);
  std::vector<BeamReturn> in = beams;  // edges are found on the unmixed returns
  int changed = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const BeamReturn &a = in[i], &b = in[i + 1];
    if (a.true_range <= 0.0 || b.true_range <= 0.0) continue;
    if (std::abs(a.true_range - b.true_range) <= jump_m) continue;
    if (std::abs(a.normal.dot(b.point - a.point)) <= jump_m ||
        std::abs(b.normal.dot(a.point - b.point)) <= jump_m)
      continue;                      // one surface (slanted), or a corner: no jump
    const double e = rng.uniform();  // the jump at beam i + e steps
    // Beams on a's side (j <= i) reach across to b's surface, and the other way round.
    for (int side = 0; side < 2; ++side) {
      const BeamReturn& other = side == 0 ? b : a;
      for (int j = side == 0 ? i : i + 1; j >= 0 && j < n; j += side == 0 ? -1 : 1) {
        const BeamReturn& own = in[j];
        if (own.true_range <= 0.0 || beams[j].range <= 0.0f) break;
        const double dist = side == 0 ? (i - j + e) * step : (j - i - 1 + (1.0 - e)) * step;
        const double alpha =
            footprint_radius(own.true_range, exit_diameter_m, divergence_rad) / own.true_range;
        if (dist >= alpha) break;
        const double f = disc_fraction_beyond(dist / alpha);
        const double wa = (1.0 - f) * own.power, wb = f * other.power;
        if (wa + wb <= 0.0) break;
        const double mixed = (wa * own.true_range + wb * other.true_range) / (wa + wb);
        beams[j].range = static_cast<float>(beams[j].range + (mixed - own.true_range));
        ++changed;
      }
    }
  }
  return changed;
}

void incidence_probabilities(const Material& m, double incidence_rad, double& p_return,
                             double& p_mirror) {
  // A specular return straight back within a few degrees of normal incidence (the pane or the
  // steel acts as a mirror back into the receiver), else the diffuse share falls with cos.
  constexpr double kSpecularLobeRad = 0.035;  // 2 deg
  const double c = std::cos(incidence_rad);
  const double lobe = std::exp(-std::pow(incidence_rad / kSpecularLobeRad, 2));
  p_return = std::max(lobe, m.p_return * c);
  // Of the rest, the mirrored share: the material's own at normal incidence, rising to all of it
  // at grazing incidence as Fresnel reflectance does (Schlick: R0 + (1 - R0)(1 - cos)^5).
  const double rest = 1.0 - m.p_return;
  const double r0 = rest > 0.0 ? std::clamp(m.p_mirror / rest, 0.0, 1.0) : 0.0;
  const double mirror_share = r0 + (1.0 - r0) * std::pow(1.0 - c, 5);
  p_mirror = (1.0 - p_return) * mirror_share;
}

}  // namespace traverse::sim
