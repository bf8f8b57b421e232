#include "trajectory.hpp"

#include <algorithm>
#include <cstdlib>
#include <iterator>

namespace traverse::evaluator {

void sort_unique(Trajectory& trajectory) {
  std::stable_sort(trajectory.begin(), trajectory.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.utime < b.utime; });
  trajectory.erase(
      std::unique(trajectory.begin(), trajectory.end(),
                  [](const StampedPose& a, const StampedPose& b) { return a.utime == b.utime; }),
      trajectory.end());
}

const StampedPose* pose_at(const Trajectory& trajectory, int64_t utime, int64_t tolerance_us) {
  const auto it = std::lower_bound(trajectory.begin(), trajectory.end(), utime,
                                   [](const StampedPose& p, int64_t t) { return p.utime < t; });
  const StampedPose* best = nullptr;
  if (it != trajectory.end()) best = &*it;
  if (it != trajectory.begin() && (!best || utime - std::prev(it)->utime < best->utime - utime)) {
    best = &*std::prev(it);
  }
  if (!best || std::abs(best->utime - utime) > tolerance_us) return nullptr;
  return best;
}

ReferenceInterpolator::ReferenceInterpolator(const Trajectory& reference, MatchConfig config)
    : reference_(reference), config_(config) {
  travel_m_.reserve(reference_.size());
  double travel_m = 0.0;
  for (std::size_t i = 0; i < reference_.size(); ++i) {
    if (i > 0) {
      travel_m += (reference_[i].pose.translation() - reference_[i - 1].pose.translation()).norm();
    }
    travel_m_.push_back(travel_m);
  }
}

std::optional<ReferenceInterpolator::Sample> ReferenceInterpolator::at(int64_t utime) const {
  if (reference_.empty() || utime < reference_.front().utime || utime > reference_.back().utime) {
    return std::nullopt;  // no extrapolation
  }
  // b: first reference pose at or after utime; a: the one before it.
  const auto it = std::lower_bound(reference_.begin(), reference_.end(), utime,
                                   [](const StampedPose& p, int64_t t) { return p.utime < t; });
  const std::size_t b = static_cast<std::size_t>(it - reference_.begin());
  if (reference_[b].utime == utime) return Sample{reference_[b].pose, travel_m_[b]};
  const std::size_t a = b - 1;
  const int64_t gap_us = reference_[b].utime - reference_[a].utime;
  const int64_t to_edge_us = std::min(utime - reference_[a].utime, reference_[b].utime - utime);
  if (gap_us > config_.max_reference_gap_us && to_edge_us > config_.edge_tolerance_us) {
    return std::nullopt;
  }
  const double s = static_cast<double>(utime - reference_[a].utime) / static_cast<double>(gap_us);
  return Sample{interpolate(reference_[a].pose, reference_[b].pose, s),
                travel_m_[a] + s * (travel_m_[b] - travel_m_[a])};
}

}  // namespace traverse::evaluator
