// The backend's state on disk (backend_state.hpp): a backend node dropped mid-drive without
// finishing (as a SIGKILL leaves it) and started again on its state directory goes on with the
// same graph, its final key poses as close to the truth as an undisturbed run's; a damaged state
// is refused; a backend that missed scans keeps going on the ones it has.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "backend_node.hpp"
#include "drive_feed.hpp"

namespace traverse::backend {
namespace {

class BackendStateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("traverse-backend-state-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    config_.backend.frontend_sigma_xy_m = 0.015;  // the drifting drive's real precision
    config_.backend.frontend_sigma_theta_rad = 0.005;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  static void handle_all(Bus& bus) {
    while (bus.lcm().handleTimeout(0) > 0) {
    }
  }
  // Drive steps [from, to) to the node on `bus` (a node cannot leave a bus: each gets its own).
  void feed(Bus& bus, std::size_t from, std::size_t to) {
    for (std::size_t k = from; k < to; ++k) {
      test::publish_drive_step(bus, drive_, k);
      handle_all(bus);
    }
  }
  // The RMS and the largest position error [m] of a backend's final key poses against the
  // drive's truth (both start at the same pose; every key pose is at a drive step's time).
  std::pair<double, double> key_pose_errors(const Backend& b) const {
    double sum = 0.0, worst = 0.0;
    for (const KeyPose& k : b.key_poses()) {
      const auto it = std::find(drive_.utimes.begin(), drive_.utimes.end(), k.utime);
      const Pose2& T = drive_.truth[it - drive_.utimes.begin()];
      const double e = (T.translation() - k.T_world_base.translation()).norm();
      sum += e * e;
      worst = std::max(worst, e);
    }
    return {std::sqrt(sum / static_cast<double>(b.key_poses().size())), worst};
  }

  BackendNodeConfig config_;
  test::Drive drive_ = test::drive_ellipse(18.0);
  std::filesystem::path dir_;
};

TEST_F(BackendStateTest, KilledMidDriveAndRestartedGoesOnWithTheSameGraph) {
  const std::size_t n = drive_.utimes.size(), kill = n / 2, back = kill + 5;
  std::pair<double, double> undisturbed_errors;
  std::size_t undisturbed_keys = 0;
  int undisturbed_closures = 0;
  {
    Bus bus("memq://");
    BackendNode node(bus, config_);
    feed(bus, 0, n);
    node.finish();
    undisturbed_errors = key_pose_errors(node.backend());
    undisturbed_keys = node.backend().key_poses().size();
    undisturbed_closures = static_cast<int>(node.backend().closures().size());
  }
  ASSERT_GT(undisturbed_closures, 0);
  std::size_t keys_at_kill = 0;
  {
    Bus bus("memq://");
    BackendNode node(bus, config_, {}, dir_.string());
    EXPECT_FALSE(node.resumed());
    feed(bus, 0, kill);
    keys_at_kill = node.backend().key_poses().size();
  }  // dropped without finish(): what a SIGKILL leaves is what was written by then
  std::map<std::string, double> counters;
  Bus bus("memq://");
  BackendNode node(
      bus, config_, [&](const std::string& k, double v) { counters[k] = v; }, dir_.string());
  ASSERT_TRUE(node.resumed());
  // Snapshots come at most state_period_s (1 s of data, 3 key poses) apart.
  EXPECT_GE(node.resumed()->key_poses + 4, static_cast<int>(keys_at_kill));
  EXPECT_LE(node.resumed()->key_poses, static_cast<int>(keys_at_kill));
  feed(bus, back, n);  // steps [kill, back) came while it was down: lost
  node.finish();
  node.report_counters();
  EXPECT_GT(counters.at("state_snapshots"), 0);
  EXPECT_EQ(counters.at("state_snapshot_failures"), 0);
  // As many key poses as the undisturbed run but those of the lost half second and those since
  // the last snapshot (at most 1 s), and as close to the truth: the key poses after the gap are
  // other scans (the key pose interval starts again from the resumed last key pose), so the
  // runs are compared through the truth.
  EXPECT_GE(node.backend().key_poses().size() + 6, undisturbed_keys);
  const auto [rms, worst] = key_pose_errors(node.backend());
  EXPECT_LT(rms, undisturbed_errors.first + 0.005) << rms << " " << undisturbed_errors.first;
  EXPECT_LT(worst, undisturbed_errors.second + 0.01) << worst << " " << undisturbed_errors.second;
  EXPECT_GT(node.backend().closures().size(), 0u);
}

TEST_F(BackendStateTest, DamagedStateIsRefusedNotTakenForNone) {
  {
    Bus bus("memq://");
    BackendNode node(bus, config_, {}, dir_.string());
    feed(bus, 0, 40);
    node.finish();
  }
  Bus bus("memq://");
  const auto path = dir_ / "graph.state";
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 20);  // torn
  EXPECT_THROW(BackendNode(bus, config_, {}, dir_.string()), std::runtime_error);
  std::ofstream(path, std::ios::binary) << "not a state";
  EXPECT_THROW(BackendNode(bus, config_, {}, dir_.string()), std::runtime_error);
}

// Scans lost on the way (poses still arriving): no key pose where its scan is missing, the next
// pose with a scan becomes the key pose, and the graph stays as good.
TEST_F(BackendStateTest, MissedScansLeaveGapsNotAWrongGraph) {
  const std::size_t n = drive_.utimes.size();
  std::pair<double, double> undisturbed;
  {
    Bus bus("memq://");
    BackendNode node(bus, config_);
    feed(bus, 0, n);
    node.finish();
    undisturbed = key_pose_errors(node.backend());
  }
  std::map<std::string, double> counters;
  Bus bus("memq://");
  BackendNode node(bus, config_, [&](const std::string& k, double v) { counters[k] = v; });
  for (std::size_t k = 0; k < n; ++k) {
    if (k >= 50 && k < 62) {  // 1.2 s of scans lost; their poses still come
      pose2d_t p{};
      p.utime = drive_.utimes[k];
      p.seq = static_cast<int64_t>(k);
      p.x = drive_.input[k].x();
      p.y = drive_.input[k].y();
      p.theta = drive_.input[k].theta();
      bus.publish(channels::kPoseFrontend, p);
    } else {
      test::publish_drive_step(bus, drive_, k);
    }
    handle_all(bus);
  }
  node.finish();
  node.report_counters();
  EXPECT_GT(counters.at("key_poses_without_scan"), 0);
  for (const KeyPose& k : node.backend().key_poses()) {
    EXPECT_FALSE(k.utime > drive_.utimes[50] && k.utime < drive_.utimes[62]) << k.utime;
  }
  // As close to the truth as the run without loss (the links across the gap span longer).
  const auto [rms, worst] = key_pose_errors(node.backend());
  EXPECT_LT(rms, undisturbed.first + 0.005) << rms << " " << undisturbed.first;
  EXPECT_LT(worst, undisturbed.second + 0.01) << worst << " " << undisturbed.second;
  EXPECT_GT(node.backend().closures().size(), 0u);
}

}  // namespace
}  // namespace traverse::backend
