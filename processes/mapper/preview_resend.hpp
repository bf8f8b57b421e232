// What the mapper keeps of its preview to answer a viewer that starts late (common/resend.hpp:
// the answer goes on CLOUD_PREVIEW_FULL). Keeping every preview message sent costs about 6 bytes
// a point, tens of MB on a whole route, and grows with the run. A late viewer needs a picture of
// the whole map, not every point: so the points kept are capped (resend_max_bytes), and when they
// pass the cap they are thinned on a coarser grid (preview_thinning.hpp): of the points in one
// cell of that grid, the earliest is kept (so the start of the route stays as it was). A pass
// doubles the cell while more than half the cap is left, so the next pass is at least half a cap
// of new points away (each point is thinned a bounded number of times on average). The grid
// doubles only when the map outgrows the cap at that cell size: what is kept follows the surface
// mapped, at about one point per cell of a grid that coarsens as the map grows, never the time
// spent.
//
// A pass over a full 8 MiB store takes a few hundred milliseconds. In the background mode (the
// live node) it runs on a thread of its own: add() hands the store over (a move) and keeps what
// arrives meanwhile apart; poll() merges the thinned store back when the pass is done. The
// caller's thread waits for neither, and an answer under way pauses while a pass runs. Without
// it (offline, tests) the pass runs inside add().
//
// Cells are chosen with the pose each profile was first placed with, like the preview's own
// (preview.hpp); the points sent are unchanged, in the base frame at the profile's time, so a
// viewer places them with the corrected trajectory as it does the live ones.
#pragma once

#include <cstddef>
#include <cstdint>
#include <future>
#include <vector>

#include "preview.hpp"
#include "preview_thinning.hpp"

namespace traverse::mapper {

struct PreviewResendCounters {
  int64_t compactions = 0;         // thinning passes
  int64_t points_compacted = 0;    // points dropped from what is kept, over all passes
  int64_t profiles_compacted = 0;  // profiles left with no point, dropped
  double compact_total_s = 0;      // [s] wall time of the passes, wherever they ran
  double compact_max_s = 0;        // [s] the longest pass
  // [s] what thinning held up the caller of add() and poll(), in all and at worst: the whole
  // pass without the background mode, handing over and merging back with it.
  double blocked_total_s = 0;
  double blocked_max_s = 0;
};

class PreviewResend {
 public:
  // `cell_m` [m]: the preview's grid; `max_bytes` [bytes]: the cap on bytes(); `background`: the
  // passes run on a thread of their own (then call poll() now and then).
  PreviewResend(double cell_m, int64_t max_bytes, bool background = false);
  ~PreviewResend();  // waits for a pass under way
  PreviewResend(const PreviewResend&) = delete;
  PreviewResend& operator=(const PreviewResend&) = delete;

  // A profile's preview points as sent live (parts of one profile, same utime, are merged).
  void add(const PreviewProfile& profile);
  // Merges a background pass that has finished, and starts the next when what arrived meanwhile
  // put the store over its cap; true when there was one.
  bool poll();
  // Waits for a background pass under way, if any, merges it, and passes again while the store is
  // over its cap (not counted as blocked: the node never waits; the end of a bench or test does).
  void wait();
  bool thinning() const { return pass_.valid(); }
  // Where an answer stands: the profile it sends next, and that profile's first point not sent.
  struct Position {
    int64_t utime = 0;      // [us]
    std::size_t point = 0;  // index into the profile's kept points
    friend auto operator<=>(const Position&, const Position&) = default;
  };
  // Where an answer stood when a listener asked: its round (`lap`) and its position in it.
  struct Mark {
    int64_t lap = 0;
    Position at;
  };
  // A late listener asked. With no answer under way, next() goes through everything kept from
  // the oldest profile. With one under way, it is not restarted (its listeners would get its start
  // twice, and listeners joining one after another would keep it from ever ending): it goes on to
  // the newest profile, then round from the oldest to where it stood now, so the newcomer gets
  // the whole store after asking and nothing is sent more than once more than someone needs.
  // Returns where the answer stood, for went_round().
  Mark answer();
  bool resending() const { return resending_; }
  // Whether the answer has gone once round the store since `mark` (or is over): a listener that
  // asked at `mark` has had everything.
  bool went_round(const Mark& mark) const;
  // The next kept profiles of the answer, at most `max_points` points (a profile with more
  // continues in the next call): in time order to the newest profile, then, if someone joined on
  // the way, in time order again from the oldest to where it joined; empty when the answer is
  // complete or paused while a pass runs.
  std::vector<PreviewProfile> next(std::size_t max_points);

  double cell_m() const { return cell_m_; }  // [m] the grid the kept points are one per cell of
  int64_t points() const { return points_; }
  std::size_t profiles() const { return kept_.size() + pass_profiles_; }
  // [bytes] heap held: 6 bytes a point and the bookkeeping of each profile.
  int64_t bytes() const;
  const PreviewResendCounters& counters() const { return counters_; }

 private:
  struct Pass {
    KeptProfiles kept;
    double cell_m = 0;   // [m] the grid it ended at
    int64_t points = 0;  // in `kept`
    double seconds = 0;  // [s] wall time of the pass
  };
  // A thinning pass over `kept` (touches nothing else: it may run on another thread).
  static Pass run(KeptProfiles kept, double cell_m, int64_t max_bytes);
  void start_pass();
  // The pass's result in place of what it was given, what arrived meanwhile added after it.
  void merge(Pass pass);
  void count_blocked(double s);
  // Puts the answer's position on the profile it sends next: round to the oldest after the
  // newest once, and the answer over where it comes back to its stop.
  void settle();

  double cell_m_;
  int64_t max_bytes_;
  bool background_;
  KeptProfiles kept_;   // with a pass under way: what arrived since it started
  int64_t points_ = 0;  // kept_'s and the pass's
  std::future<Pass> pass_;
  std::size_t pass_profiles_ = 0;  // profiles handed to the pass under way
  int64_t pass_points_ = 0;        // ... and their points
  bool resending_ = false;
  Position next_;         // what the answer sends next
  Position stop_;         // where it ends once round the store (the last listener's join)
  bool wrapped_ = false;  // round past the newest profile since the last listener asked
  int64_t lap_ = 0;       // times round past the newest profile in this answer
  PreviewResendCounters counters_;
};

}  // namespace traverse::mapper
