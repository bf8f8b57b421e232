#include "no_return.hpp"

#include <algorithm>
#include <cmath>

namespace traverse::carmen {
namespace {

// A code holds at least this many times the beams of any value within kSpikeWindowMm of it.
constexpr int64_t kSpikeRatio = 10;
constexpr std::size_t kSpikeWindowMm = 50;

}  // namespace

RangeHistogram::RangeHistogram() : bins_(static_cast<std::size_t>(kMaxRangeM * 1000) + 1, 0) {}

void RangeHistogram::add(float range_m) {
  if (!(range_m > 0.0f)) return;
  ++total_;
  if (!(range_m <= kMaxRangeM)) {
    ++overflow_;
    return;
  }
  ++bins_[static_cast<std::size_t>(std::lround(static_cast<double>(range_m) * 1000.0))];
}

std::optional<NoReturnCode> find_no_return_code(const RangeHistogram& h, double min_fraction) {
  if (h.total() == 0) return std::nullopt;
  const double needed = std::max(1.0, min_fraction * static_cast<double>(h.total()));
  int64_t above = h.overflow();
  for (std::size_t mm = h.bins(); mm-- > 0;) {
    const int64_t n = h.count_mm(mm);
    if (static_cast<double>(n) < needed) {
      above += n;
      continue;
    }
    // The largest value held by enough beams: a code only at the top of the range, as a spike.
    if (static_cast<double>(above) >= needed) return std::nullopt;
    int64_t neighbours = 0;
    for (std::size_t d = 1; d <= kSpikeWindowMm; ++d) {
      neighbours = std::max({neighbours, h.count_mm(mm + d), mm >= d ? h.count_mm(mm - d) : 0});
    }
    if (n < kSpikeRatio * neighbours) return std::nullopt;
    return NoReturnCode{static_cast<double>(mm) / 1000.0, n,
                        static_cast<double>(n) / static_cast<double>(h.total())};
  }
  return std::nullopt;
}

}  // namespace traverse::carmen
