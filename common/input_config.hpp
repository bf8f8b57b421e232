// What every process checks on the messages it subscribes to, beyond their bytes holding what
// they claim: the `input:` section of any process's config file (Process::start reads it beside
// the process's own keys).
//
//   input:
//     max_scan_beams: 100000       # planar_scan_t with more beams is rejected (counted)
//     max_stamp_jump_s: 600        # a stamp this far from its neighbours is held, then judged
//     max_queue_bytes: 1073741824  # receive queue of a network bus; beyond it, drops (counted)
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "config.hpp"
#include "message_layout.hpp"

namespace traverse {

struct InputConfig {
  // Beams per scan: far above any real planar scanner (a SICK LMS or Hokuyo gives about 1,000, a
  // profile scanner under 20,000); a CARMEN scan of 100,000 beams took the frontend 172 s.
  int64_t max_scan_beams = 100'000;
  // [s] A stamp further than this from the previous one on its channel is held back until the
  // next message says whether the stream moved on (stamp_order.hpp). Above the longest pause in
  // the CARMEN logs (37.7 s, aces).
  double max_stamp_jump_s = 600.0;
  // [bytes] Messages waiting in a network bus's receive queue; beyond it arrivals are dropped.
  int64_t max_queue_bytes = int64_t{1} << 30;

  template <class V>
  void visit(V& v) {
    v("max_scan_beams", max_scan_beams);
    v("max_stamp_jump_s", max_stamp_jump_s);
    v("max_queue_bytes", max_queue_bytes);
  }
};

inline std::optional<std::string> validate_input(const InputConfig& c) {
  ConfigCheck check;
  check.positive("max_scan_beams", c.max_scan_beams);
  check.positive("max_stamp_jump_s", c.max_stamp_jump_s);
  check.positive("max_queue_bytes", c.max_queue_bytes);
  return check.problem();
}

// The array caps the message walk applies (message_layout.hpp).
inline std::vector<ArrayLimit> array_limits(const InputConfig& c) {
  return {{"traverse.planar_scan_t", "ranges", c.max_scan_beams},
          {"traverse.planar_scan_t", "intensities8", c.max_scan_beams},
          {"traverse.planar_scan_t", "intensities16", c.max_scan_beams}};
}

}  // namespace traverse
