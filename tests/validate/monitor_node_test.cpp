// The monitor's node in-process on a memq bus: it hears every channel and every process status.
#include "monitor_node.hpp"

#include <gtest/gtest.h>

#include "process.hpp"
#include "test_messages.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse {
namespace {

process_status_t status(const std::string& name, const std::string& state,
                        int64_t decode_failures) {
  process_status_t st{};
  st.utime = now_utime();
  st.process = name;
  st.host = "test";
  st.pid = 1234;
  st.cpu_s = 0.25;
  st.rss_bytes = 5'000'000;
  st.state = state;
  channel_stats_t c{};
  c.channel = "SCAN";
  c.received = 10;
  c.decode_failures = decode_failures;
  st.channels.push_back(c);
  st.n_channels = 1;
  st.n_counters = 0;
  return st;
}

void drain(Bus& bus) {
  while (bus.lcm().handleTimeout(0) > 0) {
  }
}

TEST(MonitorNode, HearsEveryChannelAndFollowsProcesses) {
  Bus bus("memq://");
  ASSERT_TRUE(bus.good());
  MonitorNode node(bus, MonitorConfig{});
  for (int i = 0; i < 5; ++i) {
    auto scan = test::make_scan(1000 * i, 0, 181);
    bus.publish("SCAN", scan);
  }
  auto st = status("frontend", "running", 0);
  bus.publish("STATUS_FRONTEND", st);
  drain(bus);

  const int64_t now = now_utime();
  const validate::RunSummary s = node.summary(now);
  EXPECT_EQ(s.events, 6);
  ASSERT_EQ(s.channels.count("SCAN"), 1u);
  const auto& scan = s.channels.at("SCAN");
  EXPECT_EQ(scan.type, "traverse.planar_scan_t");
  EXPECT_EQ(scan.count, 5);
  EXPECT_EQ(scan.points.max, 181);
  EXPECT_EQ(scan.seq_gaps, 0);
  ASSERT_EQ(s.channels.count("STATUS_FRONTEND"), 1u);
  EXPECT_EQ(s.channels.at("STATUS_FRONTEND").type, "traverse.process_status_t");

  ASSERT_EQ(s.processes.count("frontend"), 1u);
  const auto& p = s.processes.at("frontend");
  EXPECT_EQ(p.state, "running");
  EXPECT_EQ(p.statuses, 1);
  EXPECT_EQ(p.last.received, 10);
  EXPECT_DOUBLE_EQ(p.last.cpu_s, 0.25);
  EXPECT_TRUE(s.ok) << (s.problems.empty() ? "" : s.problems.front());

  // Nothing more heard: after the timeout the process is silent and the run is not ok.
  const validate::RunSummary later = node.summary(now + 10'000'000);
  EXPECT_EQ(later.processes.at("frontend").state, "silent");
  EXPECT_FALSE(later.ok);
}

TEST(MonitorNode, ReportsBadBytesAndProblemsProcessesReport) {
  Bus bus("memq://");
  MonitorNode node(bus, MonitorConfig{});
  const uint8_t junk[] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  bus.lcm().publish("SCAN", junk, sizeof(junk));
  bus.lcm().publish("STATUS_BROKEN", junk, sizeof(junk));
  auto st = status("backend", "running", 4);
  bus.publish("STATUS_BACKEND", st);
  auto stop = status("backend", "stopping", 4);
  bus.publish("STATUS_BACKEND", stop);
  drain(bus);

  const validate::RunSummary s = node.summary(now_utime() + 60'000'000);
  EXPECT_EQ(s.channels.at("SCAN").decode_failures, 1);
  EXPECT_EQ(s.status_decode_failures, 1);
  EXPECT_EQ(s.processes.at("backend").state, "stopped");  // said so: not silent
  EXPECT_EQ(s.processes.at("backend").last.decode_failures, 4);
  EXPECT_FALSE(s.ok);
  EXPECT_GE(s.problems.size(), 3u);
}

TEST(MonitorNode, ConfigKeysAreChecked) {
  MonitorConfig cfg;
  load_config_text("status_timeout_s: 1.5\n", "monitor.yaml", cfg);
  EXPECT_DOUBLE_EQ(cfg.status_timeout_s, 1.5);
  EXPECT_THROW(load_config_text("status_timeout: 1.5\n", "monitor.yaml", cfg), ConfigError);
}

}  // namespace
}  // namespace traverse
