#include "trajectory_store.hpp"

#include <algorithm>

namespace traverse::mapper {

Pose2 interpolate_linear(int64_t t0, const Pose2& a, int64_t t1, const Pose2& b, int64_t utime) {
  if (t1 <= t0 || utime <= t0) return a;
  if (utime >= t1) return b;
  const double s = static_cast<double>(utime - t0) / static_cast<double>(t1 - t0);
  const Eigen::Vector2d t = a.translation() + s * (b.translation() - a.translation());
  return Pose2(t.x(), t.y(), wrap_angle(a.theta() + s * wrap_angle(b.theta() - a.theta())));
}

bool TrajectoryStore::valid(const TrajectorySegment& segment) {
  return segment.utimes.size() >= 2 && segment.utimes.size() == segment.T_world_base.size() &&
         std::is_sorted(segment.utimes.begin(), segment.utimes.end()) &&
         segment.utimes.front() != segment.utimes.back();
}

bool TrajectoryStore::set(TrajectorySegment segment, bool* replaced) {
  if (!valid(segment)) return false;
  const int64_t t0 = segment.utime_first();
  auto it = segments_.find(t0);
  if (replaced) *replaced = it != segments_.end();
  segments_[t0] = std::move(segment);
  return true;
}

const TrajectorySegment* TrajectoryStore::segment_at(int64_t utime) const {
  auto it = segments_.upper_bound(utime);
  if (it == segments_.begin()) return nullptr;
  --it;
  return utime <= it->second.utime_last() ? &it->second : nullptr;
}

std::optional<Pose2> TrajectoryStore::pose_at(int64_t utime) const {
  const TrajectorySegment* s = segment_at(utime);
  if (!s) return std::nullopt;
  auto hi = std::lower_bound(s->utimes.begin(), s->utimes.end(), utime);
  const std::size_t j = static_cast<std::size_t>(hi - s->utimes.begin());
  if (j == 0) return s->T_world_base.front();
  return interpolate_linear(s->utimes[j - 1], s->T_world_base[j - 1], s->utimes[j],
                            s->T_world_base[j], utime);
}

bool TrajectoryStore::covers(int64_t t0, int64_t t1) const {
  int64_t t = t0;
  while (true) {
    const TrajectorySegment* s = segment_at(t);
    if (!s) return false;
    if (s->utime_last() >= t1) return true;
    t = s->utime_last();
    // The next segment must start exactly where this one ends.
    auto next = segments_.find(t);
    if (next == segments_.end()) return false;
  }
}

std::optional<int64_t> TrajectoryStore::last_utime() const {
  if (segments_.empty()) return std::nullopt;
  return segments_.rbegin()->second.utime_last();
}

}  // namespace traverse::mapper
