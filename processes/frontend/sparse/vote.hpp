// The vote of a sparse-scan ensemble (ensemble.hpp) on one step.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "se2.hpp"

namespace traverse::frontend {

// Whether two steps (or poses) agree: within 0.15 m and 0.05 rad (about three times what a
// member's steps scatter where all are right, a tenth of a typical sparse step).
bool poses_agree(const Pose2& a, const Pose2& b);

// The vote on each member's step from its last pose to its new one, in its own map: the step
// with the most steps agreeing with it (on a tie the earliest), how many those are, and the second
// moment of all steps about it (x, y in the frame `R_map_last` turns them into, [m^2, rad^2]).
struct StepVote {
  std::size_t chosen = 0;
  int support = 0;
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
};
StepVote vote_on_steps(const std::vector<Pose2>& steps, const Eigen::Matrix2d& R_map_last);

}  // namespace traverse::frontend
