#include "vote.hpp"

#include <cmath>

#include "correlative_search.hpp"

namespace traverse::frontend {
namespace {

constexpr double kAgreeM = 0.15, kAgreeRad = 0.05;

}  // namespace

bool poses_agree(const Pose2& a, const Pose2& b) {
  return (a.translation() - b.translation()).norm() < kAgreeM &&
         std::abs(wrap_angle(a.theta() - b.theta())) < kAgreeRad;
}

StepVote vote_on_steps(const std::vector<Pose2>& steps, const Eigen::Matrix2d& R_map_last) {
  StepVote v;
  if (steps.empty()) return v;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    int support = 0;
    for (const Pose2& other : steps) support += poses_agree(steps[i], other) ? 1 : 0;
    if (support > v.support) {
      v.support = support;
      v.chosen = i;
    }
  }
  // The members' steps as poses of equal weight about the chosen one.
  const Pose2& step = steps[v.chosen];
  correlative::ScoreSpread spread;
  for (const Pose2& other : steps) {
    Eigen::Vector3d d;
    d.head<2>() = R_map_last * (other.translation() - step.translation());
    d.z() = wrap_angle(other.theta() - step.theta());
    spread.add(1.0, d);
  }
  v.spread = spread.about_chosen();
  return v;
}

}  // namespace traverse::frontend
