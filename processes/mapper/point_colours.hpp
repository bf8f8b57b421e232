// The annotator's verdict on the points (seed 004): every point takes the accuracy level and colour
// of the key pose nearest in time to the point's own time (the key poses are about a third of a
// second apart, so that is the key pose whose stretch of trajectory placed it). Annotations arrive
// on ANNOTATIONS and are replaced by id whenever a loop closure changes them, so an export always
// shows the newest ones. Points before any annotation keep no level (-1) and grey.
#pragma once

#include <array>
#include <cstdint>
#include <map>

namespace traverse::mapper {

struct PointColour {
  int8_t level = -1;  // legend index of the annotations; -1: none yet
  std::array<uint8_t, 3> rgb{128, 128, 128};
};

class PointColours {
 public:
  // The annotation of key pose `id` taken at `utime` [us]. Returns true when the key pose's level
  // changed (a key pose seen for the first time counts as no change).
  bool set(int64_t id, int64_t utime, int8_t level, const std::array<uint8_t, 3>& rgb);
  // The colour of a point measured at `utime` [us].
  PointColour at(int64_t utime) const;
  std::size_t size() const { return by_utime_.size(); }

 private:
  std::map<int64_t, PointColour> by_utime_;
  std::map<int64_t, int64_t> utime_of_id_;
};

}  // namespace traverse::mapper
