#include "guidance.hpp"

#include <cmath>

namespace traverse::viewer {

Guidance guide(const std::map<int64_t, KeyAnnotation>& annotations, const Legend& legend,
               const StampedPose& now, double loop_min_age_s) {
  Guidance g;
  g.utime = now.utime;
  const int n = static_cast<int>(legend.levels.size());
  g.below.resize(static_cast<std::size_t>(n));
  const int64_t old_enough = now.utime - static_cast<int64_t>(loop_min_age_s * 1e6);
  auto distance = [&now](const KeyAnnotation& k) {
    return std::hypot(k.x - now.T_map_base.x(), k.y - now.T_map_base.y());
  };
  for (const auto& [id, k] : annotations) {
    const double d = distance(k);
    const GuidanceTarget t{id, k.x, k.y, d};
    // Worse than every bottom level below its own.
    for (int b = 0; b < k.level && b < n; ++b) {
      auto& r = g.below[static_cast<std::size_t>(b)];
      if (!r || d < r->nearest.distance_m) r = PoorRegion{t, id, id, 0};
    }
    if (k.level <= legend.best_level && k.utime <= old_enough &&
        (!g.loop_target || d < g.loop_target->distance_m)) {
      g.loop_target = t;
    }
  }
  // Each region: the run of consecutive ids worse than its bottom level around the nearest.
  for (int b = 0; b < n; ++b) {
    auto& r = g.below[static_cast<std::size_t>(b)];
    if (!r) continue;
    auto at = annotations.find(r->nearest.id);
    auto lo = at, hi = at;
    while (lo != annotations.begin()) {
      auto prev = std::prev(lo);
      if (prev->second.level <= b || prev->first + 1 != lo->first) break;
      lo = prev;
    }
    for (auto next = std::next(hi);
         next != annotations.end() && next->second.level > b && next->first == hi->first + 1;
         next = std::next(hi)) {
      hi = next;
    }
    r->first_id = lo->first;
    r->last_id = hi->first;
    r->keys = static_cast<int>(std::distance(lo, hi)) + 1;
  }
  return g;
}

}  // namespace traverse::viewer
