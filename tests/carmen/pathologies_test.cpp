// traverse-carmen on crafted logs with the pathologies of real public logs (issues of timestamps
// that carry no time, a no-return code inside the range limit, an absurd beam count, a bad
// config). Each of these failed with the driver before they were handled: all-zero stamps were
// published 1 us apart (the frontend took them for a scanner's stream), negative ones as negative
// times 0.3 s apart, whole seconds as runs 1 us apart, 32.76 m readings as hundreds of points on a
// circle round the robot, and a 100,000-beam scan as it came.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "bus.hpp"
#include "carmen_config.hpp"
#include "channels.hpp"
#include "config.hpp"
#include "crafted_logs.hpp"
#include "frontend_config.hpp"
#include "json.hpp"
#include "program.hpp"
#include "traverse/odometry_t.hpp"
#include "traverse/planar_scan_t.hpp"
#include "traverse/pose2d_t.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse::carmen::test {
namespace {

namespace fs = std::filesystem;

// The frontend's gap beyond which scans are matched as sparse, and the driver's nominal spacing,
// as the shipped configs set them (or default them): a log without time must look sparse.
int64_t frontend_sparse_gap_us() {
  frontend::FrontendConfig frontend;
  load_config("configs/frontend.yaml", frontend);
  return frontend.matcher.wide_search_gap_us;
}

TEST(CarmenConfigs, NominalSpacingIsSparseForTheFrontend) {
  carmen::CarmenConfig driver;
  load_config("configs/carmen.yaml", driver);
  EXPECT_GT(driver.nominal_scan_period_s * 1e6, static_cast<double>(frontend_sparse_gap_us()));
}

struct TimeCase {
  const char* name;
  std::vector<std::string> (*stamps)(int n);
  const char* fault;  // in the JSON's timestamps_fault
  friend void PrintTo(const TimeCase& c, std::ostream* os) { *os << c.name; }
};

std::vector<std::string> zero(int n) { return stamps_all_zero(n); }
std::vector<std::string> negative_then_coarse(int n) { return stamps_negative_then_coarse(n, 5); }
std::vector<std::string> whole_seconds(int n) { return stamps_whole_seconds(n, 4); }

class TimelessLog : public ::testing::TestWithParam<TimeCase> {};

// Scans come out as a log subsampled by travel: strictly increasing, every gap longer than the
// frontend's sparse gap, never negative; odometry one per scan at the scan's time; the verdict in
// the JSON and a warning.
TEST_P(TimelessLog, IsSaidAndRestampedAsSubsampledByTravel) {
  const TimeCase& c = GetParam();
  const auto dir = temp_dir(std::string("timeless-") + c.name);
  CraftedLog log;
  log.poses = loop_path(0.6);
  log.stamps = c.stamps(static_cast<int>(log.poses.size()));
  ASSERT_TRUE(write_log((dir / "in.log").string(), log));
  const std::string lcm = (dir / "out.lcmlog").string();
  const auto r = run(kCarmen + " " + (dir / "in.log").string() + " --out " + lcm);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = last_line(r.output);
  EXPECT_NE(json.find("\"timestamps\":\"nominal\""), std::string::npos) << json;
  EXPECT_NE(json.find(c.fault), std::string::npos) << json;
  EXPECT_NE(r.output.find("carry no time"), std::string::npos) << r.output;

  const auto scans = read_channel<planar_scan_t>(lcm, channels::kScanHorizontal);
  ASSERT_EQ(scans.size(), log.poses.size());
  const int64_t gap_us = frontend_sparse_gap_us();
  for (std::size_t i = 0; i < scans.size(); ++i) {
    EXPECT_GT(scans[i].utime, 0) << i;
    if (i > 0) {
      EXPECT_GT(scans[i].utime - scans[i - 1].utime, gap_us) << i;
    }
  }
  const auto odometry = read_channel<odometry_t>(lcm, channels::kOdometry);
  ASSERT_EQ(odometry.size(), scans.size());
  for (std::size_t i = 0; i < odometry.size(); ++i) {
    EXPECT_EQ(odometry[i].utime, scans[i].utime);
    // The crafted odometry is the true pose: the chain starts there and follows it.
    EXPECT_NEAR(odometry[i].x, log.poses[i].x(), 1e-5);
    EXPECT_NEAR(odometry[i].y, log.poses[i].y(), 1e-5);
  }
  const auto poses = read_channel<pose2d_t>(lcm, channels::kPoseReference);
  ASSERT_EQ(poses.size(), scans.size());
  for (std::size_t i = 1; i < poses.size(); ++i) EXPECT_GT(poses[i].utime, poses[i - 1].utime);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, TimelessLog,
    ::testing::Values(TimeCase{"all_zero", zero, "equal (0 s)"},
                      TimeCase{"negative_then_coarse", negative_then_coarse, "5 negative"},
                      TimeCase{"whole_seconds", whole_seconds, "steps repeat the stamp"}));

// Live, the verdict is in every status: timestamps_without_time 1, the scans placed nominally.
TEST(TimelessLog, LiveStatusSaysSo) {
  const std::string url = "udpm://239.255.76.67:31392?ttl=0";
  Bus bus(url);
  ASSERT_TRUE(bus.good());
  int scans = 0, statuses = 0;
  double without_time = -1.0, restamped = -1.0;
  bus.subscribe<planar_scan_t>(channels::kScanHorizontal, [&](const planar_scan_t&) { ++scans; });
  bus.subscribe<process_status_t>(channels::status_channel("carmen"),
                                  [&](const process_status_t& s) {
                                    ++statuses;
                                    for (int i = 0; i < s.n_counters; ++i) {
                                      if (s.counter_names[i] == "timestamps_without_time") {
                                        without_time = s.counter_values[i];
                                      }
                                      if (s.counter_names[i] == "scans_restamped_nominal") {
                                        restamped = s.counter_values[i];
                                      }
                                    }
                                  });
  const auto dir = temp_dir("timeless-live");
  CraftedLog log;
  log.poses = loop_path(0.6);
  log.poses.resize(8);
  log.stamps = stamps_all_zero(8);
  ASSERT_TRUE(write_log((dir / "in.log").string(), log));
  // 8 scans 3 s apart at 20x: about 1 s of wall time.
  std::thread driver([&] {
    const auto r =
        run(kCarmen + " " + (dir / "in.log").string() + " --speed 20 --lcm-url '" + url + "'");
    EXPECT_EQ(r.exit_code, 0) << r.output;
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((scans < 8 || statuses < 2) && std::chrono::steady_clock::now() < deadline) {
    bus.handle(100);
  }
  driver.join();
  for (int i = 0; i < 5; ++i) bus.handle(100);  // the final status
  EXPECT_EQ(scans, 8);
  EXPECT_GE(statuses, 2);
  EXPECT_EQ(without_time, 1.0);
  EXPECT_EQ(restamped, 8.0);
  fs::remove_all(dir);
}

// The control: a log whose stamps carry time keeps them exactly.
TEST(TimedLog, KeepsItsStamps) {
  const auto dir = temp_dir("timed");
  CraftedLog log;
  log.poses = loop_path(0.6);
  log.stamps = stamps_fine(static_cast<int>(log.poses.size()), 0.4);
  ASSERT_TRUE(write_log((dir / "in.log").string(), log));
  const std::string lcm = (dir / "out.lcmlog").string();
  const auto r = run(kCarmen + " " + (dir / "in.log").string() + " --out " + lcm);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(last_line(r.output).find("\"timestamps\":\"ipc\""), std::string::npos);
  const auto scans = read_channel<planar_scan_t>(lcm, channels::kScanHorizontal);
  ASSERT_EQ(scans.size(), log.poses.size());
  for (std::size_t i = 0; i < scans.size(); ++i) {
    EXPECT_EQ(scans[i].utime, 1'000'000'000 + static_cast<int64_t>(i) * 400'000);
  }
  // ODOM lines stamped like their scan: one message each, at that time.
  EXPECT_EQ(read_channel<odometry_t>(lcm, channels::kOdometry).size(), scans.size());
  fs::remove_all(dir);
}

// Points a consumer would take from a scan: readings inside [range_min, range_max].
int valid_points(const planar_scan_t& s) {
  int n = 0;
  for (float r : s.ranges) n += r >= s.range_min && r <= s.range_max;
  return n;
}

TEST(NoReturnCode, ACodeInsideTheRangeLimitBecomesNoPoints) {
  const auto dir = temp_dir("no-return");
  CraftedLog log;
  log.poses = loop_path(0.6);
  log.stamps = stamps_fine(static_cast<int>(log.poses.size()), 0.4);
  log.open_top = true;  // beams through the open side find nothing within 30 m
  log.no_return_text = "32.76";
  ASSERT_TRUE(write_log((dir / "in.log").string(), log));
  // The true points: beams that hit a wall (a crafted reading below 30 m).
  int beams_without_return = 0;
  {
    std::ifstream in(dir / "in.log");
    for (std::string tok; in >> tok;) beams_without_return += tok == "32.76";
  }
  ASSERT_GT(beams_without_return, 500);
  const std::string lcm = (dir / "out.lcmlog").string();
  const auto r = run(kCarmen + " " + (dir / "in.log").string() + " --out " + lcm);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = last_line(r.output);
  EXPECT_NEAR(traverse::Json::parse(json).at("no_return_code_m").get<double>(), 32.76, 1e-9)
      << json;
  EXPECT_NE(r.output.find("no-return code 32.760 m"), std::string::npos) << r.output;
  int points = 0, beams = 0;
  for (const planar_scan_t& s : read_channel<planar_scan_t>(lcm, channels::kScanHorizontal)) {
    points += valid_points(s);
    beams += s.n_ranges;
    EXPECT_LT(s.range_max, 32.76f);
    EXPECT_GT(s.range_max, 32.75f);  // a real reading of 32.75 m stays a point
  }
  EXPECT_EQ(points, beams - beams_without_return);

  // Configured instead of found: the same; and a log with no code keeps the range limit.
  std::ofstream(dir / "carmen.yaml") << "no_return_code_m: 32.76\n";
  const auto configured = run(kCarmen + " " + (dir / "in.log").string() + " --config " +
                              (dir / "carmen.yaml").string() + " --out " + lcm);
  ASSERT_EQ(configured.exit_code, 0) << configured.output;
  EXPECT_NEAR(
      traverse::Json::parse(last_line(configured.output)).at("no_return_code_m").get<double>(),
      32.76, 1e-9);
  fs::remove_all(dir);
}

TEST(BeamCount, AHugeScanIsThinnedAndCounted) {
  const auto dir = temp_dir("beams");
  {
    std::ofstream out(dir / "in.log");
    out << "FLASER 100000";
    for (int i = 0; i < 100000; ++i) out << " 2.50";
    out << " 0 0 0 0 0 0 10.0 h 10.0\n";
    out << "FLASER 3 1 2 3 0 0 0 0 0 0 11.0 h 11.0\n";
  }
  const std::string lcm = (dir / "out.lcmlog").string();
  const auto r = run(kCarmen + " " + (dir / "in.log").string() + " --out " + lcm);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = last_line(r.output);
  EXPECT_NE(json.find("\"max_beams_in_scan\":100000,\"scans_thinned\":1"), std::string::npos)
      << json;
  const auto scans = read_channel<planar_scan_t>(lcm, channels::kScanHorizontal);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_LE(scans[0].n_ranges, 4096);
  EXPECT_GE(scans[0].n_ranges, 2048);
  // The thinned beams still cover the scan's field of view.
  EXPECT_NEAR(scans[0].angle_step * scans[0].n_ranges, M_PI, 0.01);
  EXPECT_EQ(scans[1].n_ranges, 3);
  fs::remove_all(dir);
}

TEST(CarmenConfig, BadValuesAreRefusedNamingKeyAndFile) {
  const auto dir = temp_dir("config");
  std::ofstream(dir / "in.log") << "FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\n";
  for (const auto& [yaml, key] : std::vector<std::pair<std::string, std::string>>{
           {"range_min_m: 1.0\nrange_max_m: 0.5\n", "range_max_m"},
           {"max_beams: 0\n", "max_beams"},
           {"nominal_scan_period_s: -3\n", "nominal_scan_period_s"},
           {"no_return_min_fraction: 2\n", "no_return_min_fraction"},
           {"odometry_source: wheels\n", "odometry_source"},
           {"flaser_geometry: sideways\n", "flaser_geometry"},
           {"odometry_noise: {forward_m_per_sqrt_m: -1}\n", "odometry_noise.forward_m_per_sqrt_m"},
           {"range_max_m: .inf\n", "range_max_m"}}) {
    const auto cfg = dir / "carmen.yaml";
    std::ofstream(cfg) << yaml;
    const auto r = run(kCarmen + " " + (dir / "in.log").string() + " --config " + cfg.string() +
                       " --out " + (dir / "out.lcmlog").string());
    EXPECT_EQ(r.exit_code, 2) << yaml << r.output;
    EXPECT_NE(r.output.find(key), std::string::npos) << yaml << r.output;
    EXPECT_NE(r.output.find(cfg.string()), std::string::npos) << yaml << r.output;
  }
  fs::remove_all(dir);
}

// The builder's log with one 3 m step between kept scans (for the frontend's wide search, whose
// window is 2 m): exactly one such step, the others as asked.
TEST(CraftedLogs, LongStepPathHasOneLongStep) {
  const auto path = loop_path_with_long_step(0.6, 3.0);
  int long_steps = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const double d = (path[i].translation() - path[i - 1].translation()).norm();
    EXPECT_LE(d, 3.0 + 1e-9);
    long_steps += d > 2.9;
  }
  EXPECT_EQ(long_steps, 1);
  EXPECT_GT(path.size(), 50u);
}

}  // namespace
}  // namespace traverse::carmen::test
