// A log's no-return code, read from the data. Laser drivers write a beam without an echo as a
// fixed value at the top of the scanner's range (the Radish logs: 50.00 m for aces, 81.83 m for
// intel, 81.91 m for csail and freiburg; other scanners 32.76 m or 65.53 m). Taken for a range,
// such a code below the driver's range limit puts hundreds of false points on a circle round the
// robot. The code is the largest range value that at least a share of all beams hold exactly,
// when few beams lie above it and it stands out as a spike against the values just below and
// above it (a wall seen for a long time from a robot standing still spreads over several
// centimetres of values; a code does not).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace traverse::carmen {

// Counts of range readings in 1 mm bins up to kMaxRangeM; beyond it one overflow count.
class RangeHistogram {
 public:
  static constexpr double kMaxRangeM = 300.0;
  RangeHistogram();
  void add(float range_m);  // readings of 0 (or below) are not counted: they are no reading
  int64_t total() const { return total_; }
  int64_t count_mm(std::size_t mm) const { return mm < bins_.size() ? bins_[mm] : 0; }
  std::size_t bins() const { return bins_.size(); }
  int64_t overflow() const { return overflow_; }

 private:
  std::vector<int64_t> bins_;
  int64_t overflow_ = 0;
  int64_t total_ = 0;
};

struct NoReturnCode {
  double code_m = 0.0;    // [m] the value
  int64_t beams = 0;      // beams holding it
  double fraction = 0.0;  // [0..1] of all beams with a reading
};

// The code, or nullopt when no value qualifies. `min_fraction`: the share of beams a value needs.
std::optional<NoReturnCode> find_no_return_code(const RangeHistogram& histogram,
                                                double min_fraction);

}  // namespace traverse::carmen
