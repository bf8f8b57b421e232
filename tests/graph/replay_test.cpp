// Offline replay (--replay IN --record OUT, common/process.hpp) end to end on the built programs:
// the frontend answers every scan of a short Intel log, the record holds the inputs and the
// outputs, two replays give the same messages, the backend replays the frontend's record in turn,
// and a log cut inside a record is replayed up to the damage.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "graph_test_util.hpp"
#include "lcm_log.hpp"

namespace traverse::graph_test {
namespace {

constexpr int kLines = 400;  // 15 scans of the Intel log
constexpr int64_t kScans = 15;

std::string replay(const std::string& program, const std::string& config, const std::string& in,
                   const std::string& out) {
  return bin_dir() + "/traverse-" + program + " --config " + config + " --replay " + in +
         " --record " + out;
}

// Every message except the status ones (they carry wall-clock times, CPU time and memory).
std::vector<std::pair<std::string, std::vector<uint8_t>>> messages(const std::string& lcm_log) {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> out;
  LogReader reader(lcm_log);
  while (auto ev = reader.next()) {
    if (ev->channel.rfind("STATUS_", 0) != 0) out.emplace_back(ev->channel, ev->data);
  }
  EXPECT_TRUE(reader.damage().empty()) << lcm_log;
  return out;
}

int64_t count(const std::map<std::string, int64_t>& counts, const std::string& channel) {
  return counts.count(channel) ? counts.at(channel) : 0;
}

TEST(Replay, FrontendThenBackendOfflineSameOutputTwice) {
  const auto dir = temp_dir("replay");
  const std::string log = short_intel_log(dir, kLines);
  const std::string a = (dir / "a.lcmlog").string(), b = (dir / "b.lcmlog").string();
  auto r = run(replay("frontend", "configs/frontend.yaml", log, a), 60);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run(replay("frontend", "configs/frontend.yaml", log, b), 60);
  ASSERT_EQ(r.exit_code, 0) << r.output;

  const auto counts = count_channels(a);
  EXPECT_EQ(count(counts, "SCAN_HORIZONTAL"), kScans);  // the input, recorded
  EXPECT_EQ(count(counts, "POSE_FRONTEND"), kScans);    // one answer per scan
  EXPECT_GE(count(counts, "STATUS_FRONTEND"), 2);       // running ... stopped
  EXPECT_EQ(messages(a), messages(b));

  const std::string ab = (dir / "ab.lcmlog").string();
  r = run(replay("backend", "configs/backend.yaml", a, ab), 60);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto counts_ab = count_channels(ab);
  EXPECT_EQ(count(counts_ab, "POSE_FRONTEND"), kScans);
  EXPECT_GE(count(counts_ab, "KEY_POSES"), 1);
  EXPECT_GE(count(counts_ab, "STATUS_BACKEND"), 2);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(Replay, ADamagedLogIsReplayedUpToTheDamage) {
  const auto dir = temp_dir("replay-cut");
  const std::string log = short_intel_log(dir, kLines);
  const std::string cut = (dir / "cut.lcmlog").string();
  std::filesystem::copy_file(log, cut);
  // Two thirds in, plus a few bytes so that the cut falls inside a record.
  std::filesystem::resize_file(cut, std::filesystem::file_size(log) * 2 / 3 + 7);
  const std::string out = (dir / "out.lcmlog").string();
  const auto r = run(replay("frontend", "configs/frontend.yaml", cut, out), 60);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  const auto counts = count_channels(out);
  EXPECT_GT(count(counts, "POSE_FRONTEND"), 0);
  EXPECT_LT(count(counts, "POSE_FRONTEND"), kScans);
  EXPECT_EQ(count(counts, "POSE_FRONTEND"), count(counts, "SCAN_HORIZONTAL"));
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

TEST(Replay, RecordNeedsReplayAndReplayNeedsAFile) {
  auto r = run(bin_dir() + "/traverse-backend --record /tmp/never.lcmlog", 10);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = run(bin_dir() + "/traverse-backend --replay /nonexistent/in.lcmlog", 10);
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

}  // namespace
}  // namespace traverse::graph_test
