#include "people.hpp"

#include <cmath>
#include <numbers>

namespace traverse::sim {

People::People(const PeopleEffect& effect, std::vector<Person> people)
    : effect_(effect), people_(std::move(people)) {}

People::People(const PeopleEffect& effect, const World& world, const Trajectory& trajectory,
               Rng rng)
    : effect_(effect) {
  if (effect.per_minute <= 0.0) return;
  const double end = trajectory.duration_s();
  const double margin = effect.body_radius_m + 0.1;
  double t = 0.0;
  while (true) {
    t += -std::log(1.0 - rng.uniform()) * 60.0 / effect.per_minute;  // Poisson arrivals
    if (t >= end) break;
    for (int attempt = 0; attempt < 8; ++attempt) {
      // Somewhere 2-8 m ahead of where the cart will be in 1-4 s, walking along its heading (either
      // way) or across in any direction.
      const double tc = std::min(end, t + rng.uniform(1.0, 4.0));
      const Pose2 cart = trajectory.nominal_pose(tc);
      const Eigen::Vector2d start =
          cart * Eigen::Vector2d(rng.uniform(2.0, 8.0), rng.uniform(-1.2, 1.2));
      const double heading = rng.bernoulli(0.5)
                                 ? cart.theta() + (rng.bernoulli(0.5) ? 0.0 : std::numbers::pi)
                                 : rng.uniform(-std::numbers::pi, std::numbers::pi);
      Person p;
      p.t0 = t;
      p.t1 = std::min(end, t + rng.uniform(effect.walk_min_s, effect.walk_max_s));
      p.start = start;
      p.dir = Eigen::Vector2d(std::cos(heading), std::sin(heading));
      p.speed = rng.uniform(effect.speed_min_mps, effect.speed_max_mps);
      p.phase = rng.uniform(0.0, 2.0 * std::numbers::pi);
      // The whole walk in free space, and never close to the cart.
      bool ok = true;
      for (double tt = p.t0; ok && tt <= p.t1; tt += 0.1) {
        const Eigen::Vector2d q = p.at(tt);
        ok = world.clearance_2d(q, 0.0, 1.8) >= margin &&
             (q - trajectory.nominal_pose(tt).translation()).norm() >= 0.8;
      }
      if (!ok) continue;
      people_.push_back(p);
      break;
    }
  }
}

void People::cylinders_at(double t, const Eigen::Vector2d& centre, double range,
                          std::vector<Cylinder>& out) const {
  for (const Person& p : people_) {
    if (t < p.t0 || t >= p.t1) continue;
    const Eigen::Vector2d body = p.at(t);
    if ((body - centre).norm() > range + 1.0) continue;
    // Gait: one stride (two steps) per 2 x step_length of travel; at knee height a leg swings
    // about +- 0.3 step lengths about the hip, the two legs in opposition.
    const double psi = p.phase + std::numbers::pi * (t - p.t0) * p.speed / effect_.step_length_m;
    const Eigen::Vector2d side(-p.dir.y(), p.dir.x());
    const double swing = 0.3 * effect_.step_length_m * std::sin(psi);
    for (const double s : {-1.0, 1.0}) {
      const Eigen::Vector2d leg = body + s * effect_.hip_half_width_m * side + s * swing * p.dir;
      out.push_back({leg, effect_.leg_radius_m, 0.0, 0.85, kPersonMaterial});
    }
    out.push_back({body, effect_.body_radius_m, 0.85, 1.75, kPersonMaterial});
  }
}

}  // namespace traverse::sim
