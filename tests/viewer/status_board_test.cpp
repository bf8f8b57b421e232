// The status board: message rates and CPU from two statuses, restarts and stale processes.
#include "status_board.hpp"

#include <gtest/gtest.h>

namespace traverse::viewer {
namespace {

StatusReport report(int64_t utime_s, double uptime_s, double cpu_s, int64_t received) {
  StatusReport r;
  r.process = "frontend";
  r.utime = utime_s * 1'000'000;
  r.uptime_s = uptime_s;
  r.cpu_s = cpu_s;
  r.received = received;
  r.published = received / 2;
  return r;
}

TEST(StatusBoard, RatesCpuRestartsAndStaleness) {
  StatusBoard board(3.0);
  ASSERT_TRUE(board.update(report(100, 10, 1.0, 1000)));
  ASSERT_TRUE(board.update(report(102, 12, 1.5, 1200)));
  const ProcessRow& row = board.rows().at("frontend");
  EXPECT_DOUBLE_EQ(row.in_hz, 100.0);
  EXPECT_DOUBLE_EQ(row.out_hz, 50.0);
  EXPECT_DOUBLE_EQ(row.cpu_percent, 25.0);
  EXPECT_FALSE(board.update(report(101, 13, 2.0, 1300)));  // older than the one held
  // The last status of a stopping process, a millisecond after the one before: rates kept.
  StatusReport last = report(102, 12, 1.5, 1210);
  last.utime += 1000;
  ASSERT_TRUE(board.update(last));
  EXPECT_DOUBLE_EQ(board.rows().at("frontend").in_hz, 100.0);
  // Restarted (uptime back to 1 s): the counts start again, no negative rate.
  ASSERT_TRUE(board.update(report(103, 1, 0.1, 10)));
  EXPECT_DOUBLE_EQ(board.rows().at("frontend").in_hz, 100.0);
  board.age(105'000'000);
  EXPECT_FALSE(board.rows().at("frontend").stale);
  board.age(107'000'000);
  EXPECT_TRUE(board.rows().at("frontend").stale);
}

}  // namespace
}  // namespace traverse::viewer
