#include "process_tracker.hpp"

#include "report.hpp"

#include <gtest/gtest.h>

namespace traverse::validate {
namespace {

ProcessReport report(const std::string& name, int64_t seq, const std::string& state = "running",
                     int32_t pid = 42) {
  ProcessReport r;
  r.process = name;
  r.pid = pid;
  r.seq = seq;
  r.state = state;
  r.cpu_s = 0.5 * static_cast<double>(seq);
  r.rss_bytes = 1000 + seq;
  return r;
}

constexpr int64_t kSecond = 1'000'000;  // [us]

TEST(ProcessTracker, FollowsAProcessAndItsGaps) {
  ProcessTracker t(3.0);
  t.add("STATUS_FRONTEND", 10 * kSecond, report("frontend", 0));
  t.add("STATUS_FRONTEND", 11 * kSecond, report("frontend", 1));
  t.add("STATUS_FRONTEND", 13 * kSecond, report("frontend", 3));  // one status lost
  const auto s = t.summary(14 * kSecond).at("frontend");
  EXPECT_EQ(s.channel, "STATUS_FRONTEND");
  EXPECT_EQ(s.state, "running");
  EXPECT_EQ(s.statuses, 3);
  EXPECT_NEAR(s.silent_s, 1.0, 1e-9);
  EXPECT_NEAR(*s.max_status_gap_s, 2.0, 1e-9);
  EXPECT_EQ(s.status_seq_gaps, 1);
  EXPECT_EQ(s.restarts, 0);
  EXPECT_DOUBLE_EQ(s.last.cpu_s, 1.5);
  EXPECT_EQ(s.peak_rss_bytes, 1003);
}

TEST(ProcessTracker, AProcessNotHeardForLongerThanTheTimeoutIsSilent) {
  ProcessTracker t(3.0);
  t.add("STATUS_A", 0, report("a", 0));
  EXPECT_EQ(t.summary(3 * kSecond).at("a").state, "running");
  EXPECT_EQ(t.summary(3 * kSecond + 1).at("a").state, "silent");
}

TEST(ProcessTracker, AProcessThatSaidStoppingIsStoppedNotSilent) {
  ProcessTracker t(3.0);
  t.add("STATUS_A", 0, report("a", 0));
  t.add("STATUS_A", kSecond, report("a", 1, "stopping"));
  const auto s = t.summary(100 * kSecond).at("a");
  EXPECT_EQ(s.state, "stopped");
  EXPECT_EQ(s.last.state, "stopping");
}

TEST(ProcessTracker, AProcessThatSaidStoppedLongAgoIsNotSilent) {
  // A process's last status after its shutdown work (an export) says "stopped"; the monitor's
  // summary comes seconds later. Before: "silent for 3.2 s", and a clean run was not ok.
  ProcessTracker t(3.0);
  t.add("STATUS_MAPPER", 0, report("mapper", 0));
  t.add("STATUS_MAPPER", kSecond, report("mapper", 1, "stopping"));
  t.add("STATUS_MAPPER", 6 * kSecond, report("mapper", 2, "stopped"));
  const auto s = t.summary(10 * kSecond).at("mapper");
  EXPECT_EQ(s.state, "stopped");
  EXPECT_TRUE(process_problems(t.summary(10 * kSecond)).empty());
}

TEST(ProcessTracker, LossesBeyondTheThresholdsAreProblems) {
  ProcessTracker t(3.0);
  ProcessReport r = report("frontend", 0);
  t.add("STATUS_FRONTEND", 0, r);
  r = report("frontend", 1);
  r.missed = 238;
  r.queue_dropped = 2;
  r.rejected = 1;
  t.add("STATUS_FRONTEND", 6 * kSecond, r);  // 6 s without a status: stopped or hung
  const auto problems = process_problems(t.summary(6 * kSecond));
  ASSERT_EQ(problems.size(), 4u);
  EXPECT_NE(problems[0].find("no status for 6.0 s"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("238 messages missed"), std::string::npos) << problems[1];
  EXPECT_NE(problems[2].find("2 messages dropped by its receive queue"), std::string::npos);
  EXPECT_NE(problems[3].find("1 messages rejected"), std::string::npos);
  Thresholds lenient;
  lenient.max_status_gap_s = 10.0;
  lenient.max_missed = 500;
  lenient.max_queue_dropped = 5;
  lenient.max_rejected = 1;
  EXPECT_TRUE(process_problems(t.summary(6 * kSecond), lenient).empty());
  lenient.timing = false;  // a replay: statuses carry no timing
  lenient.max_status_gap_s = 1.0;
  EXPECT_TRUE(process_problems(t.summary(6 * kSecond), lenient).empty());
}

TEST(ProcessTracker, ANewPidIsARestartNotASequenceGap) {
  ProcessTracker t(3.0);
  t.add("STATUS_A", 0, report("a", 7, "running", 100));
  t.add("STATUS_A", kSecond, report("a", 0, "running", 200));
  const auto s = t.summary(kSecond).at("a");
  EXPECT_EQ(s.restarts, 1);
  EXPECT_EQ(s.status_seq_gaps, 0);
  EXPECT_EQ(s.last.pid, 200);
}

TEST(ProcessTracker, ProcessesAreKeptApart) {
  ProcessTracker t(3.0);
  t.add("STATUS_A", 0, report("a", 0));
  t.add("STATUS_B", 0, report("b", 0));
  t.add("STATUS_B", kSecond, report("b", 1));
  const auto all = t.summary(kSecond);
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all.at("a").statuses, 1);
  EXPECT_EQ(all.at("b").statuses, 2);
}

}  // namespace
}  // namespace traverse::validate
