// The corrected trajectory T_world_base as the mapper sees it: segments between consecutive key
// poses, each replaced whole when an optimisation moves it. Answers the pose at any covered time
// by interpolation between the two nearest poses (linear in position, shortest way in heading).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "se2.hpp"

namespace traverse::mapper {

struct TrajectorySegment {
  int64_t key_id_first = 0;         // key pose that starts the segment
  std::vector<int64_t> utimes;      // [us] increasing, at least two
  std::vector<Pose2> T_world_base;  // one per time
  int64_t utime_first() const { return utimes.front(); }
  int64_t utime_last() const { return utimes.back(); }
};

class TrajectoryStore {
 public:
  // Stores or replaces the segment starting at its first time; false if it has fewer than two
  // poses or unsorted times. `replaced` tells whether a segment with that start existed.
  bool set(TrajectorySegment segment, bool* replaced = nullptr);
  // What set() accepts: at least two poses, one per time, times increasing.
  static bool valid(const TrajectorySegment& segment);

  // Pose at `utime`, nullopt when no segment covers it.
  std::optional<Pose2> pose_at(int64_t utime) const;
  // Segment covering `utime` (the later one at a shared end), or nullptr.
  const TrajectorySegment* segment_at(int64_t utime) const;
  // True when [t0, t1] is covered without a gap.
  bool covers(int64_t t0, int64_t t1) const;

  std::size_t size() const { return segments_.size(); }
  std::optional<int64_t> last_utime() const;

 private:
  std::map<int64_t, TrajectorySegment> segments_;  // by first time
};

// Pose between two stamped poses at `utime` (clamped to [t0, t1]).
Pose2 interpolate_linear(int64_t t0, const Pose2& a, int64_t t1, const Pose2& b, int64_t utime);

}  // namespace traverse::mapper
