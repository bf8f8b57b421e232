// Messages lost on the way: a copy of the sample log with five horizontal scans cut out (their
// sequence numbers skipped, as a lossy network would) goes through the frontend and the backend.
// The frontend counts the five in its status, the monitor's verdict fails the run naming the
// loss, and the graph keeps going on what it has.
#include <gtest/gtest.h>

#include <lcm/lcm-cpp.hpp>

#include "graph_test_util.hpp"

namespace traverse::graph_test {
namespace {

// Copies `in` to `out` without the SCAN_HORIZONTAL messages number [first, first + n) (counted
// from 0 on the channel); returns the messages kept on that channel.
int64_t drop_scans(const std::string& in, const std::string& out, int first, int n) {
  lcm::LogFile reader(in, "r"), writer(out, "w");
  EXPECT_TRUE(reader.good() && writer.good());
  int index = 0;
  int64_t kept = 0;
  while (const lcm::LogEvent* ev = reader.readNextEvent()) {
    if (ev->channel == "SCAN_HORIZONTAL") {
      const int i = index++;
      if (i >= first && i < first + n) continue;
      ++kept;
    }
    lcm::LogEvent copy = *ev;
    writer.writeEvent(&copy);
  }
  return kept;
}

TEST(MessageLoss, SkippedSequenceNumbersAreCountedAndFailTheVerdict) {
  const auto dir = temp_dir("loss");
  const std::string lossy = (dir / "lossy.lcmlog").string();
  const int64_t kept =
      drop_scans("logs/office-s2_seed1_20s-22s_profile-every-5th.lcmlog", lossy, 30, 5);
  ASSERT_EQ(kept, 91);
  const auto r = run("TRAVERSE_BIN_DIR=" + bin_dir() +
                         " scripts/run-graph.sh --deploy configs/deploy/pipeline.yaml --stages "
                         "frontend,backend --offline --log " +
                         lossy + " --out " + (dir / "run").string(),
                     120);
  // Every process ran to the end; the verdict fails (exit 3) and says what was lost.
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_NE(r.output.find("frontend: 5 messages missed"), std::string::npos) << r.output;

  int64_t frontend_missed = -1;
  for (const auto& s : statuses((dir / "run" / "run.lcmlog").string())) {
    if (s.channel == "STATUS_FRONTEND")
      frontend_missed = s.missed.count("SCAN_HORIZONTAL") ? s.missed.at("SCAN_HORIZONTAL") : -2;
  }
  EXPECT_EQ(frontend_missed, 5);
  // The frontend went on with the scans it had, and the backend built its graph from them.
  const auto counts = count_channels((dir / "run" / "run.lcmlog").string());
  EXPECT_EQ(counts.count("POSE_FRONTEND") ? counts.at("POSE_FRONTEND") : 0, kept);
  EXPECT_GT(counts.count("KEY_POSES") ? counts.at("KEY_POSES") : 0, 0);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
