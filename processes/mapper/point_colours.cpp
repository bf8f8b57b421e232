#include "point_colours.hpp"

#include <iterator>

namespace traverse::mapper {

bool PointColours::set(int64_t id, int64_t utime, int8_t level, const std::array<uint8_t, 3>& rgb) {
  bool changed = false;
  if (auto it = utime_of_id_.find(id); it != utime_of_id_.end()) {
    auto old = by_utime_.find(it->second);
    changed = old != by_utime_.end() && old->second.level != level;
    if (it->second != utime && old != by_utime_.end()) by_utime_.erase(old);
  }
  utime_of_id_[id] = utime;
  by_utime_[utime] = {level, rgb};
  return changed;
}

PointColour PointColours::at(int64_t utime) const {
  if (by_utime_.empty()) return {};
  auto hi = by_utime_.lower_bound(utime);
  if (hi == by_utime_.end()) return std::prev(hi)->second;
  if (hi == by_utime_.begin()) return hi->second;
  auto lo = std::prev(hi);
  return utime - lo->first <= hi->first - utime ? lo->second : hi->second;
}

}  // namespace traverse::mapper
