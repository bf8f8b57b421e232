// What the mapper keeps of its preview to answer a viewer that starts late (common/resend.hpp:
// the answer goes on CLOUD_PREVIEW_FULL). Keeping every preview message sent costs about 6 bytes
// a point, tens of MB on a whole route, and grows with the run. A late viewer needs a picture of
// the whole map, not every point: so the points kept are capped (resend_max_bytes), and when they
// pass the cap they are thinned on a coarser grid: of the points in one cell of that grid, the
// earliest is kept (so the start of the route stays as it was). A pass thins at the current grid
// first (what came since the last pass), and doubles the cell while more than half the cap is
// left, so the next pass is at least half a cap of new points away (each point is thinned a
// bounded number of times on average). The grid doubles only when the map outgrows the cap at
// that cell size: what is kept follows the surface mapped, at about one point per cell of a grid
// that coarsens as the map grows, never the time spent.
//
// Cells are chosen with the pose each profile was first placed with, like the preview's own
// (preview.hpp); the points sent are unchanged, in the base frame at the profile's time, so a
// viewer places them with the corrected trajectory as it does the live ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "preview.hpp"

namespace traverse::mapper {

struct PreviewResendCounters {
  int64_t compactions = 0;         // thinning passes
  int64_t points_compacted = 0;    // points dropped from what is kept, over all passes
  int64_t profiles_compacted = 0;  // profiles left with no point, dropped
  double compact_total_s = 0;      // [s] wall time spent thinning
  double compact_max_s = 0;        // [s] the longest pass
};

class PreviewResend {
 public:
  // `cell_m` [m]: the preview's grid; `max_bytes` [bytes]: the cap on bytes().
  PreviewResend(double cell_m, int64_t max_bytes);

  // A profile's preview points as sent live (parts of one profile, same utime, are merged).
  void add(const PreviewProfile& profile);
  // A late listener asked: next() goes through everything kept from the oldest profile again.
  void restart();
  bool resending() const { return resending_; }
  // The next kept profiles of the answer in time order, at most `max_points` points (a profile
  // with more continues in the next call); empty when the answer is complete.
  std::vector<PreviewProfile> next(std::size_t max_points);

  double cell_m() const { return cell_m_; }  // [m] the grid the kept points are one per cell of
  int64_t points() const { return points_; }
  std::size_t profiles() const { return kept_.size(); }
  // [bytes] heap held: 6 bytes a point and the bookkeeping of each profile.
  int64_t bytes() const;
  const PreviewResendCounters& counters() const { return counters_; }

  // What a kept profile costs besides its points (its map node and record) [bytes].
  static constexpr int64_t kProfileBytes = 96;

 private:
  struct Kept {
    float x = 0, y = 0, theta = 0;  // [m, m, rad] the first placement's pose (chooses cells)
    std::vector<std::array<int16_t, 3>> p_base_mm;
  };
  void compact();
  void thin();  // one point per cell of cell_m_, the earliest

  double cell_m_;
  int64_t max_bytes_;
  std::map<int64_t, Kept> kept_;  // by utime
  int64_t points_ = 0;
  bool resending_ = false;
  int64_t next_utime_ = 0;      // [us] the answer's next profile
  std::size_t next_point_ = 0;  // ... and its first point not yet sent
  PreviewResendCounters counters_;
};

}  // namespace traverse::mapper
