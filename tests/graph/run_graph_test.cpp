// scripts/run-graph.sh end to end on a few seconds of the Intel data replayed at 8x: every
// process's status once a second in the recording, two runs at once that stay apart, a process
// that dies failing the run, and Ctrl-C stopping it cleanly.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "graph_test_util.hpp"
#include "json.hpp"

namespace traverse::graph_test {
namespace {

// The first 400 lines of the Intel log: 15 scans over 32.7 s of log time, 4.1 s at 8x.
constexpr int kLines = 400;
constexpr int64_t kScans = 15;

std::string run_graph(const std::string& deploy, const std::string& log,
                      const std::filesystem::path& out) {
  return "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " + deploy + " --log " +
         log + " --out " + out.string() + " --speed 8 --grace 0.5";
}

// The launcher's summary: the last line of its output that is a JSON object (null if none).
Json summary(const std::string& output) {
  std::istringstream in(output);
  Json last;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.front() == '{') last = Json::parse(line, nullptr, false);
  }
  return last.is_discarded() ? Json() : last;
}

// Status channels about once a second: count within the span of the run they cover.
void expect_status_once_a_second(const std::string& lcm_log) {
  std::map<std::string, std::vector<int64_t>> times;
  for (const auto& s : statuses(lcm_log)) times[s.channel].push_back(s.utime);
  ASSERT_TRUE(times.count("STATUS_MONITOR")) << lcm_log;
  for (const auto& [channel, t] : times) {
    ASSERT_GE(t.size(), 2u) << channel;
    const double span_s = 1e-6 * static_cast<double>(t.back() - t.front());
    EXPECT_GT(span_s, 3.0) << channel << " covers too little of the run";
    // One per second plus the first and the final "stopping" status.
    EXPECT_GE(static_cast<double>(t.size()), std::floor(span_s)) << channel;
    EXPECT_LE(static_cast<double>(t.size()), std::ceil(span_s) + 2.0) << channel;
    for (std::size_t i = 1; i < t.size(); ++i) {
      EXPECT_LT(t[i] - t[i - 1], 1'500'000) << channel << ": status gap at message " << i;
    }
  }
}

TEST(RunGraph, RecordsTheReplayAndEveryStatusOnceASecond) {
  const auto dir = temp_dir("status");
  const std::string log = short_intel_log(dir, kLines);
  const auto r = run(run_graph("configs/deploy/pipeline.yaml", log, dir / "run"), 120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto counts = count_channels((dir / "run" / "run.lcmlog").string());
  EXPECT_EQ(counts.count("SCAN_HORIZONTAL") ? counts.at("SCAN_HORIZONTAL") : 0, kScans);
  EXPECT_EQ(counts.count("POSE_REFERENCE") ? counts.at("POSE_REFERENCE") : 0, kScans);
  expect_status_once_a_second((dir / "run" / "run.lcmlog").string());
  EXPECT_TRUE(std::filesystem::exists(dir / "run" / "monitor.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "run" / "run-graph.json"));
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

// --record-without leaves channels out of run.lcmlog, live (traverse-record) and offline (the last
// stage's record copied without them), and nothing else: the graph still hears them.
TEST(RunGraph, RecordWithoutLeavesTheNamedChannelsOut) {
  const auto dir = temp_dir("record-without");
  const std::string log = short_intel_log(dir, kLines);
  for (const std::string mode : {"live", "offline"}) {
    const auto out = dir / mode;
    const auto r = run(run_graph("configs/deploy/pipeline.yaml", log, out) +
                           " --stages frontend --record-without \"SCAN_.*|ODOMETRY\"" +
                           (mode == "offline" ? " --offline" : ""),
                       120);
    ASSERT_EQ(r.exit_code, 0) << mode << "\n" << r.output;
    const auto counts = count_channels((out / "run.lcmlog").string());
    EXPECT_EQ(counts.count("SCAN_HORIZONTAL"), 0u) << mode;
    EXPECT_EQ(counts.count("ODOMETRY"), 0u) << mode;
    EXPECT_EQ(counts.count("POSE_REFERENCE") ? counts.at("POSE_REFERENCE") : 0, kScans) << mode;
    // The frontend heard the scans the record leaves out: one pose each. Offline it hears every
    // one; live, a machine busy with other work can make it miss some (the count is in its status).
    const int64_t poses = counts.count("POSE_FRONTEND") ? counts.at("POSE_FRONTEND") : 0;
    if (mode == "offline") {
      EXPECT_EQ(poses, kScans) << mode;
    } else {
      EXPECT_GT(poses, 0) << mode;
      EXPECT_LE(poses, kScans) << mode;
    }
    EXPECT_GT(counts.count("STATUS_FRONTEND") ? counts.at("STATUS_FRONTEND") : 0, 0) << mode;
  }
  const auto bad = run(
      run_graph("configs/deploy/pipeline.yaml", log, dir / "bad") + " --record-without \"SCAN_(\"",
      60);
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(RunGraph, TwoRunsAtTheSameTimeDoNotHearEachOther) {
  const auto dir = temp_dir("concurrent");
  const std::string log = short_intel_log(dir, kLines);
  const std::string a = run_graph("configs/deploy/pipeline.yaml", log, dir / "a");
  const std::string b = run_graph("configs/deploy/pipeline.yaml", log, dir / "b");
  const auto r = run("(" + a + " > " + (dir / "a.out").string() + " 2>&1; echo $? > " +
                         (dir / "a.rc").string() + ") & (" + b + " > " + (dir / "b.out").string() +
                         " 2>&1; echo $? > " + (dir / "b.rc").string() + ") & wait",
                     120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::set<std::string> urls;
  for (const char* run_name : {"a", "b"}) {
    int rc = -1;
    std::ifstream(dir / (std::string(run_name) + ".rc")) >> rc;
    std::stringstream out;
    out << std::ifstream(dir / (std::string(run_name) + ".out")).rdbuf();
    EXPECT_EQ(rc, 0) << out.str();
    urls.insert(summary(out.str()).value("url", ""));
    const std::string rec = (dir / run_name / "run.lcmlog").string();
    const auto counts = count_channels(rec);
    // Each recording holds its own replay exactly once, and one monitor.
    EXPECT_EQ(counts.count("SCAN_HORIZONTAL") ? counts.at("SCAN_HORIZONTAL") : 0, kScans) << rec;
    std::set<int32_t> monitor_pids;
    for (const auto& s : statuses(rec)) {
      if (s.channel == "STATUS_MONITOR") monitor_pids.insert(s.pid);
    }
    EXPECT_EQ(monitor_pids.size(), 1u) << rec << " heard another run's monitor";
  }
  EXPECT_EQ(urls.size(), 2u) << "both runs used the same LCM URL";
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(RunGraph, FailsAndNamesAProcessThatDied) {
  const auto dir = temp_dir("died");
  const std::string log = short_intel_log(dir, 200);
  const auto deploy = (dir / "deploy.yaml").string();
  std::ofstream(deploy) << "processes:\n"
                           "  - name: doomed\n"
                           "    program: traverse-carmen\n"
                           "    args: [/nonexistent/carmen.log]\n";
  const auto r = run(run_graph(deploy, log, dir / "run"), 60);
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("'doomed' died"), std::string::npos) << r.output;
  EXPECT_EQ(summary(r.output)["failed"], Json::array({"doomed"})) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "run" / "doomed.log"));
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(RunGraph, CtrlCStopsEverythingCleanly) {
  const auto dir = temp_dir("interrupt");
  const std::string log = short_intel_log(dir, kLines);
  // At 1x the replay would take 33 s; SIGINT (what Ctrl-C sends) after 3 s.
  const std::string cmd = "TRAVERSE_BIN_DIR=" + bin_dir() +
                          " scripts/run-graph.sh --deploy configs/deploy/pipeline.yaml --log " +
                          log + " --out " + (dir / "run").string() + " --speed 1 & pid=$!; " +
                          "sleep 3; kill -INT $pid; wait $pid; echo exit=$?";
  const auto r = run(cmd, 60);
  EXPECT_NE(r.output.find("exit=130"), std::string::npos) << r.output;
  EXPECT_EQ(summary(r.output)["interrupted"], true) << r.output;
  EXPECT_EQ(summary(r.output)["failed"], Json::array()) << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "run" / "monitor.json"));
  const auto counts = count_channels((dir / "run" / "run.lcmlog").string());
  EXPECT_GT(counts.count("STATUS_MONITOR") ? counts.at("STATUS_MONITOR") : 0, 2);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(RunGraph, RejectsADeploymentWithAnUnknownKey) {
  const auto dir = temp_dir("badkey");
  const auto deploy = (dir / "deploy.yaml").string();
  std::ofstream(deploy) << "processes:\n  - name: x\n    program: traverse-carmen\n    confg: a\n";
  const auto r = run(run_graph(deploy, deploy, dir / "run"), 30);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("confg"), std::string::npos) << r.output;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
