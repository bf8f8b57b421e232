// What time a CARMEN log's messages are published at.
//
// A CARMEN message carries two clocks, the ipc timestamp (its time) and the logger's. Real logs
// hold both good and useless ones: stamps all zero, negative, printed with 6 significant digits
// (1e4 s steps at 1.1e9 s), a few out of order. The whole log's scans are surveyed first
// (ClockStats) and one plan made (plan_time):
//   ipc      the ipc stamps carry time: used, a scan stamped no later than the one before it is put
//            1 us after it (counted: real logs have a few, and file order is motion order);
//   logger   the ipc stamps carry no time but the logger's do: those are used the same way;
//   nominal  neither carries time: scans are placed TimestampPolicy::nominal_period_s apart, as a
//            log subsampled by travel (the logs that lose their time are such logs: the Radish
//            corrected logs keep a scan every half metre or so). The period must exceed the
//            frontend's matcher.wide_search_gap_us, so that it treats the scans as sparse.
// Stamps carry no time when any is negative, any is printed coarser than
// TimestampPolicy::max_quantum_s, or they are all equal or more than a quarter of the steps
// between them repeat or go back (or, for the logger clock, a scan has none).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "carmen_log.hpp"

namespace traverse::carmen {

struct TimestampPolicy {
  double max_quantum_s = 1.0;     // [s] stamps printed coarser than this carry no time
  double nominal_period_s = 3.0;  // [s] spacing of scans when no clock carries time
};

// One clock's stamps over a log's scans, in file order.
class ClockStats {
 public:
  // A scan's stamp on this clock (nullopt: the line has none) and its printed resolution [s].
  void add(std::optional<int64_t> utime, double quantum_s, double max_quantum_s);
  // Why these stamps carry no time, in words ("all 237 equal (0 s)"); empty when they do.
  std::string fault() const;

  int64_t scans() const { return scans_; }
  int64_t coarse() const { return coarse_; }               // printed coarser than max_quantum_s
  double max_quantum_s() const { return max_quantum_s_; }  // [s] coarsest resolution seen
  std::optional<int64_t> first() const { return first_; }  // [us] the first scan's stamp

 private:
  int64_t scans_ = 0, missing_ = 0, negative_ = 0, coarse_ = 0, repeats_ = 0, backwards_ = 0;
  double max_quantum_s_ = 0.0;
  std::optional<int64_t> first_, previous_;
};

enum class Clock { kIpc, kLogger, kNominal };
const char* clock_name(Clock clock);  // "ipc", "logger", "nominal"

struct TimePlan {
  Clock clock = Clock::kIpc;
  std::string ipc_fault;            // why the ipc stamps carry no time; empty when they do
  std::string logger_fault;         // the same for the logger's (when it was looked at)
  int64_t nominal_first_utime = 0;  // [us] kNominal: the first scan's time
  int64_t nominal_period_us = 0;    // [us] kNominal: the spacing of scans
};

// The plan for a log whose scans gave these statistics. kNominal starts at the first ipc stamp
// when that is a positive time, else at one period.
TimePlan plan_time(const ClockStats& ipc, const ClockStats& logger, const TimestampPolicy& policy);

// A message's stamp on a clock (kNominal has none).
std::optional<int64_t> stamp_on(const Stamp& stamp, Clock clock);

// Gives each scan its time by a plan, never going backwards.
class ScanClock {
 public:
  explicit ScanClock(TimePlan plan) : plan_(std::move(plan)) {}
  // The time [us] of the next scan in file order (`line`: its line number, for the report).
  int64_t next(const Stamp& stamp, int64_t line);

  int64_t backwards_count() const { return backwards_count_; }
  const std::vector<int64_t>& backwards_lines() const { return backwards_lines_; }  // first 100
  int64_t max_backstep_us() const { return max_backstep_us_; }  // [us] largest correction made

 private:
  TimePlan plan_;
  int64_t scans_ = 0;
  std::optional<int64_t> last_;
  int64_t backwards_count_ = 0;
  std::vector<int64_t> backwards_lines_;
  int64_t max_backstep_us_ = 0;
};

// Which of a sequence of stamps to keep so that the kept ones strictly increase: the longest such
// subsequence (in file order, which is the order of the motion: a stamp out of line is the one
// dropped, not every stamp after it). nullopt entries are never kept. O(n log n).
std::vector<bool> longest_increasing(const std::vector<std::optional<int64_t>>& utimes);

}  // namespace traverse::carmen
