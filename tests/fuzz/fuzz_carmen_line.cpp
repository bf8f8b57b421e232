// Fuzz target: one line of a CARMEN log, read with every FLASER beam geometry. parse_line must
// never throw, and a scan it accepts must have finite numbers.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <variant>

#include "carmen_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace traverse::carmen;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (FlaserGeometry g :
       {FlaserGeometry::kStandard, FlaserGeometry::kHalfOpen, FlaserGeometry::kClosed,
        FlaserGeometry::kCentered, FlaserGeometry::kReversed}) {
    const ParsedLine parsed = parse_line(text, 1, g);
    if (const Scan* s = std::get_if<Scan>(&parsed)) {
      if (!std::isfinite(s->x_m) || !std::isfinite(s->y_m) || !std::isfinite(s->theta_rad) ||
          !std::isfinite(s->beams.angle_first) || !std::isfinite(s->beams.angle_step)) {
        std::abort();
      }
    }
  }
  return 0;
}
