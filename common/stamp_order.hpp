// Orders one channel's messages by their own stamps (utime) without letting one bad stamp block
// the channel. A message stamped before the last one delivered is out of order (dropped). A
// message stamped more than `max_jump_us` away from the last one, ahead or behind, is held back:
// if the next message follows it closely (in order, within max_jump_us), the stream really moved
// on -- a pause, a restarted clock -- and both are delivered (a time jump); otherwise the held
// one is an outlier and dropped. Before, one scan stamped near INT64_MAX made the next 55 of 96
// scans drop as out of order (on IMU, 240 of 401).
//
// A message held back is delivered one message late, and only after a jump larger than
// max_jump_us; the last message of a channel, if it jumped, is never confirmed and never
// delivered (counted as an outlier by finish()).
#pragma once

#include <cstdint>
#include <optional>

namespace traverse {

class StampOrder {
 public:
  explicit StampOrder(int64_t max_jump_us) : max_jump_us_(max_jump_us) {}

  struct Step {
    bool release_held = false;  // deliver the held message now, before this one
    bool deliver = false;       // deliver this message (after the held one, if released)
    bool hold = false;          // keep this message back until the next one decides
    bool dropped_held = false;  // the held message was an outlier: dropped
    bool out_of_order = false;  // this message is before the last one delivered: dropped
  };
  Step next(int64_t utime);
  // End of the stream: a message still held is an outlier; true if there was one.
  bool finish();

  bool holding() const { return held_.has_value(); }
  int64_t out_of_order() const { return out_of_order_; }
  int64_t outliers() const { return outliers_; }
  int64_t jumps() const { return jumps_; }

 private:
  // |a - b| > max_jump_us_, without overflow.
  bool far(int64_t a, int64_t b) const;

  int64_t max_jump_us_;
  std::optional<int64_t> last_;  // stamp of the last message delivered
  std::optional<int64_t> held_;  // stamp of the message held back
  int64_t out_of_order_ = 0, outliers_ = 0, jumps_ = 0;
};

}  // namespace traverse
