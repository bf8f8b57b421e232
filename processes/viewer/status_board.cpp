#include "status_board.hpp"

namespace traverse::viewer {
namespace {

constexpr double kMinRateInterval_s = 0.5;  // [s] statuses come once a second

}  // namespace

bool StatusBoard::update(const StatusReport& r) {
  auto [it, fresh] = rows_.try_emplace(r.process);
  ProcessRow& row = it->second;
  if (!fresh) {
    const double dt = (r.utime - row.last.utime) * 1e-6;
    if (dt <= 0) return false;
    // A restarted process starts its counts again: no rate from across the restart. A status
    // sent right after another (the last one, when a process stops) gives no rate either: over a
    // millisecond the counts say nothing.
    if (r.uptime_s >= row.last.uptime_s && dt >= kMinRateInterval_s) {
      row.in_hz = (r.received - row.last.received) / dt;
      row.out_hz = (r.published - row.last.published) / dt;
      row.cpu_percent = 100.0 * (r.cpu_s - row.last.cpu_s) / dt;
    }
  }
  row.last = r;
  row.stale = false;
  return true;
}

void StatusBoard::age(int64_t now_utime) {
  for (auto& [name, row] : rows_) {
    row.stale = (now_utime - row.last.utime) * 1e-6 > stale_after_s_;
  }
}

}  // namespace traverse::viewer
