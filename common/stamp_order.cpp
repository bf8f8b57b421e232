#include "stamp_order.hpp"

namespace traverse {

bool StampOrder::far(int64_t a, int64_t b) const {
  // The distance as unsigned: exact for any two int64 values.
  const uint64_t d = a > b ? static_cast<uint64_t>(a) - static_cast<uint64_t>(b)
                           : static_cast<uint64_t>(b) - static_cast<uint64_t>(a);
  return d > static_cast<uint64_t>(max_jump_us_);
}

StampOrder::Step StampOrder::next(int64_t utime) {
  Step s;
  if (held_) {
    if (utime >= *held_ && !far(utime, *held_)) {
      s.release_held = true;  // the stream moved on: the held message starts its new time line
      ++jumps_;
      last_ = held_;
    } else {
      ++outliers_;  // far from both neighbours
      s.dropped_held = true;
    }
    held_.reset();
  }
  if (!last_) {
    last_ = utime;
    s.deliver = true;
  } else if (far(utime, *last_)) {
    held_ = utime;
    s.hold = true;
  } else if (utime < *last_) {
    ++out_of_order_;
    s.out_of_order = true;
  } else {
    last_ = utime;
    s.deliver = true;
  }
  return s;
}

bool StampOrder::finish() {
  if (!held_) return false;
  held_.reset();
  ++outliers_;
  return true;
}

}  // namespace traverse
