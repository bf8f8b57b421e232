// People walking through the scans. Each person appears somewhere ahead of the cart, walks a
// straight line through free space at 1-1.5 m/s for a few seconds and leaves (steps out of the
// modelled space), never nearer than 0.8 m to the cart. A walking person is two legs that swing
// back and forth in step (what a scanner at knee height sees), under a torso.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "effects.hpp"
#include "rng.hpp"
#include "trajectory.hpp"
#include "world.hpp"

namespace traverse::sim {

struct Person {
  double t0 = 0.0, t1 = 0.0;                        // [s] since the route's start: appears, leaves
  Eigen::Vector2d start = Eigen::Vector2d::Zero();  // [m] world, at t0
  Eigen::Vector2d dir = Eigen::Vector2d::UnitX();   // unit walking direction
  double speed = 1.2;                               // [m/s]
  double phase = 0.0;                               // [rad] gait phase at t0
  Eigen::Vector2d at(double t) const { return start + (t - t0) * speed * dir; }
};

// Material index that cylinders of people carry in RayHit (not one of the world's materials).
inline constexpr int kPersonMaterial = -2;

class People {
 public:
  // Places the people along the cart's route (seeded by `rng`).
  People(const PeopleEffect& effect, const World& world, const Trajectory& trajectory, Rng rng);
  // A person walking from `start` along `dir` from t0 to t1 (tests).
  People(const PeopleEffect& effect, std::vector<Person> people);

  // Appends the leg and torso cylinders of everyone there at time t [s] whose position is within
  // `range` [m] of `centre` (world xy).
  void cylinders_at(double t, const Eigen::Vector2d& centre, double range,
                    std::vector<Cylinder>& out) const;
  const std::vector<Person>& people() const { return people_; }
  double reflectivity() const { return effect_.reflectivity; }

 private:
  PeopleEffect effect_;
  std::vector<Person> people_;
};

}  // namespace traverse::sim
