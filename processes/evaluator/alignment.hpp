// Bringing an estimated trajectory, which starts in its own frame, into the reference frame.
//
// - none: the estimate is taken as already in the reference frame (a driver or the graph gave the
//   estimator the reference's start pose).
// - first_pose: the estimate's first matched pose is tied to the reference pose at that time, as
//   seed 000 does ("tied to the reference ... only by setting the starting pose to the reference
//   starting pose"). The default: it is what the paper's Table 2 reports, and it is a no-op when
//   the estimator already starts at the reference pose.
// - se2: the rigid motion minimising the sum of squared position differences over all matched
//   pairs (Umeyama 1991 without scale, via Eigen::umeyama). Flatters a drifting estimate; use it
//   to separate shape error from start-up error.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "se2.hpp"

namespace traverse::evaluator {

enum class Align { kNone, kFirstPose, kSe2 };

std::optional<Align> parse_align(const std::string& name);  // "none", "first_pose", "se2"
std::string align_name(Align align);

struct Alignment {
  Align used = Align::kNone;  // se2 falls back to first_pose when the positions are degenerate
  Pose2 T_ref_est;            // maps estimate-frame poses into the reference frame
};

// T_ref_est from matched pairs (est[i] and ref[i] at the same time, in time order).
Alignment compute_alignment(Align align, const std::vector<Pose2>& est,
                            const std::vector<Pose2>& ref);

}  // namespace traverse::evaluator
