// The time plan of a CARMEN log: which stamps carry time, what scans are timed by when none do,
// and which odometry stamps are kept in time order.
#include "log_time.hpp"

#include <gtest/gtest.h>

namespace traverse::carmen {
namespace {

constexpr double kMaxQuantumS = 1.0;

ClockStats stats(const std::vector<std::optional<int64_t>>& utimes, double quantum_s = 1e-6) {
  ClockStats s;
  for (const auto& t : utimes) s.add(t, quantum_s, kMaxQuantumS);
  return s;
}

TEST(ClockStats, FineStampsCarryTime) {
  EXPECT_EQ(stats({1'000'000, 1'400'000, 1'800'000, 2'200'000}).fault(), "");
  // A few repeats and steps back (intel's subsampled log has 4 of 909) still carry time.
  std::vector<std::optional<int64_t>> t;
  for (int i = 0; i < 20; ++i) t.push_back(1'000'000 * i);
  t[5] = t[4];
  t[9] = 7'500'000;
  EXPECT_EQ(stats(t).fault(), "");
}

TEST(ClockStats, AllEqualStampsCarryNoTime) {
  const auto f = stats({0, 0, 0, 0, 0}).fault();
  EXPECT_EQ(f, "all 5 equal (0 s)");
}

TEST(ClockStats, NegativeStampsCarryNoTime) {
  EXPECT_NE(stats({-1'500'000, -1'200'000, 1'000'000, 2'000'000}).fault().find("2 negative"),
            std::string::npos);
}

TEST(ClockStats, CoarseStampsCarryNoTime) {
  ClockStats s;
  s.add(-1'000'000, 0.1, kMaxQuantumS);
  s.add(1'134'860'000'000'000, 1e4, kMaxQuantumS);
  s.add(1'134'860'000'000'000, 1e4, kMaxQuantumS);
  const std::string f = s.fault();
  EXPECT_NE(f.find("1 negative"), std::string::npos) << f;
  EXPECT_NE(f.find("2 printed to 1e+04 s only"), std::string::npos) << f;
  EXPECT_EQ(s.coarse(), 2);
  EXPECT_DOUBLE_EQ(s.max_quantum_s(), 1e4);
}

TEST(ClockStats, WholeSecondsForScansFasterThanThatCarryNoTime) {
  // Printed to 1 s (not coarse by itself) while scans come 4 a second: most steps repeat.
  std::vector<std::optional<int64_t>> t;
  for (int i = 0; i < 40; ++i) t.push_back(1'000'000'000'000 + 1'000'000 * (i / 4));
  const std::string f = stats(t, 1.0).fault();
  EXPECT_NE(f.find("30 of 39 steps repeat the stamp"), std::string::npos) << f;
}

TEST(ClockStats, MissingLoggerStampsCarryNoTime) {
  EXPECT_NE(stats({1'000'000, std::nullopt, 3'000'000}).fault().find("1 of 3 missing"),
            std::string::npos);
}

TEST(PlanTime, PrefersIpcThenLoggerThenNominal) {
  const ClockStats fine = stats({1'000'000, 2'000'000, 3'000'000});
  const ClockStats zero = stats({0, 0, 0});
  EXPECT_EQ(plan_time(fine, zero, {}).clock, Clock::kIpc);
  const TimePlan logger = plan_time(zero, fine, {});
  EXPECT_EQ(logger.clock, Clock::kLogger);
  EXPECT_EQ(logger.ipc_fault, "all 3 equal (0 s)");
  const TimePlan nominal = plan_time(zero, zero, {1.0, 2.5});
  EXPECT_EQ(nominal.clock, Clock::kNominal);
  EXPECT_EQ(nominal.nominal_period_us, 2'500'000);
  EXPECT_EQ(nominal.nominal_first_utime, 2'500'000);  // the first stamp is no positive time
  const ClockStats coarse = stats({1'134'860'000'000'000, 1'134'860'000'000'000}, 1e4);
  EXPECT_EQ(plan_time(coarse, coarse, {1.0, 3.0}).nominal_first_utime, 1'134'860'000'000'000);
}

TEST(ScanClock, NominalPlanSpacesScansEvenly) {
  const TimePlan plan = plan_time(stats({0, 0, 0}), stats({0, 0, 0}), {1.0, 3.0});
  ScanClock clock(plan);
  Stamp s;
  EXPECT_EQ(clock.next(s, 1), 3'000'000);
  EXPECT_EQ(clock.next(s, 2), 6'000'000);
  EXPECT_EQ(clock.next(s, 3), 9'000'000);
  EXPECT_EQ(clock.backwards_count(), 0);
}

TEST(ScanClock, NeverGoesBackwards) {
  ScanClock clock(TimePlan{});
  Stamp s;
  s.ipc_utime = 10;
  EXPECT_EQ(clock.next(s, 1), 10);
  s.ipc_utime = 5;
  EXPECT_EQ(clock.next(s, 2), 11);
  s.ipc_utime = 11;
  EXPECT_EQ(clock.next(s, 3), 12);
  s.ipc_utime = 20;
  EXPECT_EQ(clock.next(s, 4), 20);
  EXPECT_EQ(clock.backwards_count(), 2);
  EXPECT_EQ(clock.backwards_lines(), (std::vector<int64_t>{2, 3}));
  EXPECT_EQ(clock.max_backstep_us(), 5);
}

TEST(ScanClock, LoggerPlanUsesTheLoggerStamps) {
  TimePlan plan;
  plan.clock = Clock::kLogger;
  ScanClock clock(plan);
  Stamp s;
  s.ipc_utime = 0;
  s.logger_utime = 42;
  EXPECT_EQ(clock.next(s, 1), 42);
}

TEST(LongestIncreasing, DropsTheStampOutOfLineNotTheOnesAfterIt) {
  // 26.5 s comes too early in file order (intel's ODOM lines): it is the one dropped.
  const std::vector<std::optional<int64_t>> t = {25'500'000, 26'508'100, 25'906'800, 26'107'700,
                                                 26'307'500, 26'466'700, 27'344'600};
  EXPECT_EQ(longest_increasing(t), (std::vector<bool>{true, false, true, true, true, true, true}));
}

TEST(LongestIncreasing, EqualAndMissingStampsAreNotKept) {
  const std::vector<std::optional<int64_t>> t = {1, 1, std::nullopt, 2, 2, 3};
  const std::vector<bool> keep = longest_increasing(t);
  std::vector<int64_t> kept;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (keep[i]) kept.push_back(*t[i]);
  }
  EXPECT_EQ(kept, (std::vector<int64_t>{1, 2, 3}));
  EXPECT_FALSE(keep[2]);
  EXPECT_TRUE(longest_increasing({}).empty());
  EXPECT_EQ(longest_increasing({std::nullopt}), (std::vector<bool>{false}));
}

}  // namespace
}  // namespace traverse::carmen
