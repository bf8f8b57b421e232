// traverse-carmen as a program: --out is byte-identical run to run and matches the input; the
// summary lists malformed lines; a damaged input fails; live mode publishes every scan on the bus.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "bus.hpp"
#include "channels.hpp"
#include "lcm_log.hpp"
#include "program.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse {
namespace {

using carmen::test::kCarmen;
using carmen::test::last_line;
using carmen::test::run;
using carmen::test::temp_dir;

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(CarmenProgram, IntelToLcmLogIsCompleteAndByteIdentical) {
  const auto dir = temp_dir("intel");
  const std::string in = "../shared/data/carmen/intel-corrected.log.gz";
  const auto a = run(kCarmen + " " + in + " --out " + (dir / "a.lcmlog").string());
  const auto b = run(kCarmen + " " + in + " --out " + (dir / "b.lcmlog").string());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_EQ(read_all(dir / "a.lcmlog"), read_all(dir / "b.lcmlog"));
  const std::string json = last_line(a.output);
  EXPECT_EQ(json.front(), '{');
  EXPECT_NE(json.find("\"scans\":910,\"reference_poses\":910"), std::string::npos) << json;
  EXPECT_NE(json.find("\"malformed_lines\":[]"), std::string::npos) << json;
  // The four scans of the Intel log stamped before their predecessor (lines of the text file).
  EXPECT_NE(json.find("\"backwards_timestamps\":4,\"backwards_lines\":[5647,10805,11190,12936]"),
            std::string::npos)
      << json;

  LogReader reader((dir / "a.lcmlog").string());
  int scans = 0, poses = 0;
  int64_t previous = -1;
  while (auto ev = reader.next()) {
    EXPECT_GE(ev->utime, previous);  // event time = message time, never backwards
    previous = ev->utime;
    if (ev->channel == channels::kScanHorizontal) {
      planar_scan_t s;
      ASSERT_EQ(s.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())),
                static_cast<int>(ev->data.size()));
      EXPECT_EQ(s.utime, ev->utime);
      EXPECT_EQ(s.utime_first, s.utime_last);  // one timestamp per CARMEN scan
      EXPECT_EQ(s.frame, "laser_horizontal");
      EXPECT_EQ(s.n_ranges, 180);
      EXPECT_EQ(s.seq, scans);
      ++scans;
    } else if (ev->channel == channels::kPoseReference) {
      pose2d_t p;
      ASSERT_GT(p.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())), 0);
      EXPECT_EQ(p.parent_frame, "world");
      EXPECT_EQ(p.child_frame, "base");
      ++poses;
    }
  }
  EXPECT_EQ(scans, 910);
  EXPECT_EQ(poses, 910);
  EXPECT_TRUE(reader.damage().empty());
  std::filesystem::remove_all(dir);
}

TEST(CarmenProgram, SummaryListsMalformedLinesAndDamagedInputFails) {
  const auto dir = temp_dir("bad");
  {
    std::ofstream out(dir / "bad.log");
    out << "FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\nFLASER 3 1 x 3 0 0 0 0 0 0 2.0 h 2.0\n"
        << "ODOM 1 2\nFLASER 99999999999999999999\nFLASER 3 1 2 3 0 0 0 0 0 0 3.0 h 3.0\n";
  }
  const auto r =
      run(kCarmen + " " + (dir / "bad.log").string() + " --out " + (dir / "bad.lcmlog").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  const std::string json = last_line(r.output);
  EXPECT_NE(json.find("\"scans\":2,"), std::string::npos) << json;
  EXPECT_NE(json.find("\"malformed_lines\":[2,3,4]"), std::string::npos) << json;
  EXPECT_NE(json.find("\"skipped_by_type\":{}"), std::string::npos) << json;

  // A gzip file cut in half: what was read is written, the run fails and says why.
  const auto gz = dir / "cut.log.gz";
  run("sh -c 'zcat ../shared/data/carmen/intel-corrected.log.gz | gzip -c | head -c 200000 > " +
      gz.string() + "'");
  const auto cut = run(kCarmen + " " + gz.string() + " --out " + (dir / "cut.lcmlog").string());
  EXPECT_EQ(cut.exit_code, 1) << cut.output;
  EXPECT_NE(last_line(cut.output).find("\"input_error\":\"compressed input damaged"),
            std::string::npos)
      << cut.output;
  EXPECT_GT(std::filesystem::file_size(dir / "cut.lcmlog"), 0u);

  const auto missing = run(kCarmen + " /nonexistent/x.log --out " + (dir / "m.lcmlog").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  std::filesystem::remove_all(dir);
}

TEST(CarmenProgram, LivePublishesEveryScanAndPoseWithStatus) {
  const std::string url = "udpm://239.255.76.67:31391?ttl=0";
  Bus bus(url);
  ASSERT_TRUE(bus.good());
  int scans = 0, poses = 0, statuses = 0;
  bus.subscribe<planar_scan_t>(channels::kScanHorizontal, [&](const planar_scan_t&) { ++scans; });
  bus.subscribe<pose2d_t>(channels::kPoseReference, [&](const pose2d_t&) { ++poses; });
  bus.subscribe<process_status_t>(channels::status_channel("carmen"),
                                  [&](const process_status_t&) { ++statuses; });
  const auto dir = temp_dir("live");
  run("sh -c 'zcat ../shared/data/carmen/intel-corrected.log.gz | head -300 > " +
      (dir / "head.log").string() + "'");
  // 11 scans over 18.1 s of log time at 20x: about 0.9 s of wall time.
  std::thread driver([&] {
    const auto r =
        run(kCarmen + " " + (dir / "head.log").string() + " --speed 20 --lcm-url '" + url + "'");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(last_line(r.output).find("\"scans\":11,"), std::string::npos) << r.output;
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((scans < 11 || poses < 11 || statuses < 2) &&
         std::chrono::steady_clock::now() < deadline) {
    bus.handle(100);
  }
  driver.join();
  EXPECT_EQ(scans, 11);
  EXPECT_EQ(poses, 11);
  EXPECT_GE(statuses, 2);  // the first one and the final "stopping"
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse
