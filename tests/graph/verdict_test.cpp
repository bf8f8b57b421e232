// What the issue found passing as good, end to end on the built programs: scans that cannot be
// right reach no frontend and fail validation; a run that lost messages, or read nothing, fails
// its verdict (scripts/run-graph.sh exits non-zero), live or offline.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "graph_test_util.hpp"
#include "lcm_log.hpp"
#include "publisher.hpp"
#include "traverse/planar_scan_t.hpp"

namespace traverse::graph_test {
namespace {

constexpr int kLines = 400;  // 15 scans of the Intel log

std::string run_graph(const std::filesystem::path& log, const std::filesystem::path& out,
                      const std::string& extra) {
  return "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " +
         "configs/deploy/pipeline.yaml --log " + log.string() + " --out " + out.string() + " " +
         extra;
}

// The short Intel log with every scan's angle_step set to 0.
std::string zero_step_log(const std::filesystem::path& dir) {
  const std::string in = short_intel_log(dir, kLines);
  const std::string out = (dir / "zero-step.lcmlog").string();
  LogReader reader(in);
  LogFilePublisher log(out);
  while (auto ev = reader.next()) {
    planar_scan_t s;
    if (ev->channel != "SCAN_HORIZONTAL" ||
        s.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) < 0) {
      continue;
    }
    s.angle_step = 0.0f;
    log.publish(ev->channel, s);
  }
  return out;
}

TEST(Verdict, ZeroAngleStepScansReachNoFrontendAndFailValidation) {
  // Before: the frontend drifted 2.1 m with a millimetre covariance; validate called it clean.
  const auto dir = temp_dir("zero-step");
  const std::string log = zero_step_log(dir);
  const auto v = run(bin_dir() + "/traverse-validate " + log, 30);
  EXPECT_EQ(v.exit_code, 1) << v.output;
  EXPECT_NE(v.output.find("angle_step is 0"), std::string::npos) << v.output;
  const std::string rec = (dir / "frontend.lcmlog").string();
  const auto f = run(bin_dir() + "/traverse-frontend --config configs/frontend.yaml --replay " +
                         log + " --record " + rec,
                     60);
  ASSERT_EQ(f.exit_code, 0) << f.output;
  const auto counts = count_channels(rec);
  EXPECT_EQ(counts.count("POSE_FRONTEND"), 0u) << "the frontend matched scans that cannot be right";
  const auto g = run(run_graph(log, dir / "run", "--offline --stages frontend"), 60);
  EXPECT_EQ(g.exit_code, 3) << g.output;
  EXPECT_NE(g.output.find("frontend: 15 messages rejected"), std::string::npos) << g.output;
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(Verdict, OfflineRunOnRandomBytesOrAnEmptyLogFails) {
  const auto dir = temp_dir("garbage");
  std::mt19937 rng(25);
  {
    std::ofstream random(dir / "random.lcmlog", std::ios::binary);
    for (int i = 0; i < 4096; ++i) random.put(static_cast<char>(rng() & 0xff));
    std::ofstream empty(dir / "empty.lcmlog");
  }
  for (const char* name : {"random.lcmlog", "empty.lcmlog"}) {
    const auto r = run(
        run_graph(dir / name, dir / (std::string(name) + ".run"), "--offline --stages frontend"),
        60);
    EXPECT_EQ(r.exit_code, 3) << name << "\n" << r.output;
    EXPECT_NE(r.output.find("no readable event"), std::string::npos) << r.output;
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(Verdict, AStoppedFrontendFailsTheLiveRun) {
  // The frontend stopped 5 s (SIGSTOP) in a 16 s replay: statuses stop, messages are lost.
  // Before: "run is clean" and exit 0. Only this run's own frontend (a child of its launcher).
  const auto dir = temp_dir("sigstop");
  const std::string log = short_intel_log(dir, kLines);
  const std::string cmd = run_graph(log, dir / "run", "--speed 2 --grace 1 --stages frontend") +
                          " & pid=$!; sleep 4; f=$(pgrep -P $pid -f traverse-frontend); " +
                          "kill -STOP $f; sleep 5; kill -CONT $f; wait $pid; echo exit=$?";
  const auto r = run(cmd, 90);
  EXPECT_NE(r.output.find("exit=3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frontend: no status for"), std::string::npos) << r.output;
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(Verdict, EveryProcessReadsAndChecksTheInputSection) {
  const auto dir = temp_dir("input-section");
  std::ofstream(dir / "empty.lcmlog");
  for (const auto& [section, expected] : std::vector<std::pair<std::string, std::string>>{
           {"input:\n  max_scan_beams: 0\n", "key 'input.max_scan_beams' must be positive"},
           {"input:\n  max_scan_beamz: 5\n", "unknown key 'input.max_scan_beamz'"},
           {"input:\n  max_stamp_jump_s: 60\n", ""}}) {
    std::ofstream(dir / "densifier.yaml") << section;
    const auto r =
        run(bin_dir() + "/traverse-densifier --config " + (dir / "densifier.yaml").string() +
                " --replay " + (dir / "empty.lcmlog").string(),
            30);
    EXPECT_EQ(r.exit_code, expected.empty() ? 0 : 2) << r.output;
    EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
