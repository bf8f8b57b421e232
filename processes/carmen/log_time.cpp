#include "log_time.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace traverse::carmen {
namespace {

// More than this share of the steps between scans repeating or going back: the stamps do not
// order the scans (intel's subsampled log has 4 of 909 going back and a few repeats).
constexpr double kMaxDisorderedSteps = 0.25;

std::string seconds(int64_t utime) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g s", 1e-6 * static_cast<double>(utime));
  return buf;
}

}  // namespace

void ClockStats::add(std::optional<int64_t> utime, double quantum_s, double max_quantum_s) {
  ++scans_;
  if (!utime) {
    ++missing_;
    return;
  }
  if (!first_) first_ = utime;
  if (*utime < 0) ++negative_;
  if (quantum_s > max_quantum_s) ++coarse_;
  max_quantum_s_ = std::max(max_quantum_s_, quantum_s);
  if (previous_ && *utime == *previous_) ++repeats_;
  if (previous_ && *utime < *previous_) ++backwards_;
  previous_ = utime;
}

std::string ClockStats::fault() const {
  std::string why;
  const auto add = [&](const std::string& part) { why += (why.empty() ? "" : ", ") + part; };
  if (missing_ > 0) add(std::to_string(missing_) + " of " + std::to_string(scans_) + " missing");
  if (negative_ > 0) add(std::to_string(negative_) + " negative");
  if (coarse_ > 0) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%lld printed to %.3g s only", static_cast<long long>(coarse_),
                  max_quantum_s_);
    add(buf);
  }
  const int64_t steps = scans_ - missing_ - 1;
  if (steps > 0 && repeats_ == steps) {
    add("all " + std::to_string(steps + 1) + " equal (" + seconds(*first_) + ")");
  } else if (steps > 0 && static_cast<double>(repeats_ + backwards_) >
                              kMaxDisorderedSteps * static_cast<double>(steps)) {
    add(std::to_string(repeats_) + " of " + std::to_string(steps) + " steps repeat the stamp, " +
        std::to_string(backwards_) + " go back");
  }
  return why;
}

const char* clock_name(Clock clock) {
  switch (clock) {
    case Clock::kLogger:
      return "logger";
    case Clock::kNominal:
      return "nominal";
    case Clock::kIpc:
      break;
  }
  return "ipc";
}

TimePlan plan_time(const ClockStats& ipc, const ClockStats& logger, const TimestampPolicy& policy) {
  TimePlan plan;
  plan.ipc_fault = ipc.fault();
  if (plan.ipc_fault.empty()) return plan;
  plan.logger_fault = logger.fault();
  if (plan.logger_fault.empty() && logger.scans() > 0) {
    plan.clock = Clock::kLogger;
    return plan;
  }
  plan.clock = Clock::kNominal;
  plan.nominal_period_us = std::llround(policy.nominal_period_s * 1e6);
  plan.nominal_first_utime =
      ipc.first() && *ipc.first() > 0 ? *ipc.first() : plan.nominal_period_us;
  return plan;
}

std::optional<int64_t> stamp_on(const Stamp& stamp, Clock clock) {
  switch (clock) {
    case Clock::kIpc:
      return stamp.ipc_utime;
    case Clock::kLogger:
      return stamp.logger_utime;
    case Clock::kNominal:
      break;
  }
  return std::nullopt;
}

int64_t ScanClock::next(const Stamp& stamp, int64_t line) {
  int64_t t = 0;
  if (plan_.clock == Clock::kNominal) {
    t = plan_.nominal_first_utime + scans_ * plan_.nominal_period_us;
  } else {
    // A plan on a clock is only made when every scan has a stamp on it.
    t = stamp_on(stamp, plan_.clock).value_or(last_.value_or(0));
  }
  ++scans_;
  if (last_ && t <= *last_) {
    max_backstep_us_ = std::max(max_backstep_us_, *last_ - t);
    if (backwards_lines_.size() < LineCounts::kListed) backwards_lines_.push_back(line);
    ++backwards_count_;
    t = *last_ + 1;
  }
  last_ = t;
  return t;
}

std::vector<bool> longest_increasing(const std::vector<std::optional<int64_t>>& utimes) {
  // Patience sorting: tails[k] is the index ending the best increasing run of length k + 1 found
  // so far (the one with the smallest last stamp); parent links recover the run.
  std::vector<std::size_t> tails;
  std::vector<std::ptrdiff_t> parent(utimes.size(), -1);
  for (std::size_t i = 0; i < utimes.size(); ++i) {
    if (!utimes[i]) continue;
    const int64_t t = *utimes[i];
    const auto it = std::lower_bound(tails.begin(), tails.end(), t,
                                     [&](std::size_t j, int64_t v) { return *utimes[j] < v; });
    if (it != tails.begin()) parent[i] = static_cast<std::ptrdiff_t>(*std::prev(it));
    if (it == tails.end()) {
      tails.push_back(i);
    } else {
      *it = i;
    }
  }
  std::vector<bool> keep(utimes.size(), false);
  if (tails.empty()) return keep;
  for (std::ptrdiff_t i = static_cast<std::ptrdiff_t>(tails.back()); i >= 0; i = parent[i]) {
    keep[static_cast<std::size_t>(i)] = true;
  }
  return keep;
}

}  // namespace traverse::carmen
