#include "final_trajectory.hpp"

#include <cmath>

namespace traverse::evaluator {
namespace {

bool finite(const Pose2& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.theta());
}

}  // namespace

void KeyPoseTrajectory::update(int64_t id, const StampedPose& pose) {
  const auto [it, inserted] = by_id_.insert_or_assign(id, pose);
  if (!inserted) ++replaced_;
}

Trajectory KeyPoseTrajectory::trajectory() const {
  Trajectory t;
  t.reserve(by_id_.size());
  for (const auto& [id, p] : by_id_) {
    if (finite(p.pose)) t.push_back(p);
  }
  sort_unique(t);
  return t;
}

bool DenseTrajectory::update(DenseSegment segment) {
  const auto it = by_first_.find(segment.key_id_first);
  if (it != by_first_.end() && segment.revision < it->second.revision) {
    ++stale_;
    return false;
  }
  by_first_.insert_or_assign(segment.key_id_first, std::move(segment));
  return true;
}

Trajectory DenseTrajectory::trajectory() const {
  Trajectory t;
  for (const auto& [first, segment] : by_first_) {
    for (const StampedPose& p : segment.poses) {
      // The shared end pose: the previous segment already gave a pose at this time.
      if (!t.empty() && p.utime == t.back().utime) continue;
      if (finite(p.pose)) t.push_back(p);
    }
  }
  sort_unique(t);  // segments that overlap in time (never in a sound densifier) stay well-formed
  return t;
}

}  // namespace traverse::evaluator
