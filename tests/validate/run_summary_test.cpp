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

// Live, the receive time stepping back while the messages' own times stay in order is the clock's
// doing (said in a note); in a log, or when the messages' times go back too, it is a problem.
TEST(RunSummary, ReceiveTimesSteppingBackAloneAreNotedLiveAndFailALog) {
  tv::RunSummary s;
  tv::ChannelSummary& c = s.channels["POSE_GROUND_TRUTH"];
  c.type = "traverse.pose2d_t";
  c.count = 401;
  c.event_backwards = 1;
  c.backwards = 1;
  c.max_backstep_s = 0.000401;
  tv::judge(s, tv::Thresholds{.timing = true});
  EXPECT_TRUE(s.ok) << s.problems.front();
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("received 1 messages stamped earlier"), std::string::npos)
      << s.notes[0];
  EXPECT_NE(s.notes[0].find("401 us"), std::string::npos) << s.notes[0];
  EXPECT_EQ(s.channels["POSE_GROUND_TRUTH"].backwards, 1) << "the figures stay as measured";

  tv::judge(s, tv::Thresholds{.timing = false});
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(s.notes.empty());

  c.utime_backwards = 1;  // the message's own time went back as well: out of order
  tv::judge(s, tv::Thresholds{.timing = true});
  EXPECT_FALSE(s.ok);
  ASSERT_EQ(s.problems.size(), 1u);
  EXPECT_NE(s.problems[0].find("timestamps go backwards"), std::string::npos) << s.problems[0];
}
