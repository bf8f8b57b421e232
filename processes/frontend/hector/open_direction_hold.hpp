// Whether a scan's open directions (degeneracy.hpp) are held at a prediction that no odometry
// made: the velocity of the last poses, bounded (MatcherConfig::degeneracy_hold_without_odometry).
// That velocity is worth holding to only where the scans measured it: after they determined the
// whole pose for degeneracy_hold_after_s without a break (a cart that starts in a bare corridor
// has only the standstill it started from), and for at most degeneracy_hold_max_s after the last
// scan that did (the velocity drifts the longer it is held). With both 0 the hold is unlimited.
#pragma once

#include <cstdint>
#include <optional>

#include "frontend_config.hpp"

namespace traverse::frontend {

class OpenDirectionHold {
 public:
  explicit OpenDirectionHold(const MatcherConfig& c)
      : enabled_(c.degeneracy_hold_without_odometry),
        after_s_(c.degeneracy_hold_after_s),
        max_s_(c.degeneracy_hold_max_s) {}

  // A matched scan at `utime`; determined: its match determined the whole pose.
  void note(int64_t utime, bool determined);
  // Open directions are held without odometry at `utime`.
  bool holds(int64_t utime) const;

 private:
  bool enabled_;
  double after_s_, max_s_;
  // [us] stamp of the first scan of the current unbroken run of determined ones (none while a
  // scan leaves a direction open), and of the last scan of a run at least degeneracy_hold_after_s
  // long.
  std::optional<int64_t> run_start_utime_;
  std::optional<int64_t> measured_utime_;
};

}  // namespace traverse::frontend
