#include "open_direction_hold.hpp"

namespace traverse::frontend {

void OpenDirectionHold::note(int64_t utime, bool determined) {
  if (!determined) {
    run_start_utime_.reset();
    return;
  }
  if (!run_start_utime_) run_start_utime_ = utime;
  const double run_s = 1e-6 * static_cast<double>(utime - *run_start_utime_);
  if (run_s >= after_s_) measured_utime_ = utime;
}

bool OpenDirectionHold::holds(int64_t utime) const {
  if (!enabled_) return false;
  if (after_s_ <= 0.0 && max_s_ <= 0.0) return true;
  if (!measured_utime_) return false;
  const double since_s = 1e-6 * static_cast<double>(utime - *measured_utime_);
  return max_s_ <= 0.0 || since_s <= max_s_;
}

}  // namespace traverse::frontend
