// The run verdict: what the monitor itself missed is said (a note), what a process of the graph
// missed fails the run.
#include "run_summary.hpp"

#include <gtest/gtest.h>

namespace tv = traverse::validate;

TEST(RunSummary, TheMonitorsOwnMissesAreNotedNotFailed) {
  tv::RunSummary s;
  s.channels["IMU"].type = "traverse.imu_t";
  s.channels["IMU"].count = 1000;
  s.channels["IMU"].seq_gaps = 10;
  tv::judge(s, tv::Thresholds{.timing = false});
  EXPECT_TRUE(s.ok);
  EXPECT_TRUE(s.problems.empty());
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("the monitor missed 10"), std::string::npos);
  const traverse::Json j = traverse::Json::parse(tv::to_json(s));
  ASSERT_EQ(j["notes"].size(), 1u);
  EXPECT_EQ(j["notes"][0], s.notes[0]);
  EXPECT_EQ(j["ok"], true);
}

TEST(RunSummary, AProcessThatMissedMessagesFailsTheRun) {
  tv::RunSummary s;
  s.channels["IMU"].seq_gaps = 10;
  tv::ProcessSummary& p = s.processes["frontend"];
  p.state = "stopped";
  p.statuses = 10;
  p.last.missed = 3;
  tv::judge(s, tv::Thresholds{.timing = false});
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.problems.empty());
}
