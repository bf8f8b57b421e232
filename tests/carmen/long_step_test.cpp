// A log subsampled so sparsely that two kept scans lie 3 m apart (issue 20: real logs step 2 to
// 3.3 m between kept scans), through the driver and the frontend as programs. The long step lies
// 2.4 m beyond where the log's usual 0.6 m steps predict it, outside the wide search's window
// (matcher.wide_search_linear_window_m, 2 m, around that prediction). Issue 20 asks that the
// window grow when the odometry or the log's own step statistics say a step is long.
//
// With the log's ODOM lines as the motion prior (motion_prior.subsampled_logs) the frontend
// follows it: the sparse lag (processes/frontend/sparse/lag.hpp) judged the 3 m step long against
// the log's usual steps and moved the scan halfway between its neighbours; it now takes odometry's
// step for its second candidate and for what counts as long. Measured 2026-11-27: the long step
// 1.253 m off before that change (largest position error 0.870 m), 0.006 m after (0.014 m).
//
// Without odometry nothing in the log says this one step is long (its times are evenly spaced),
// but the scan fits nowhere in the window: the sparse widening (processes/frontend/sparse/
// widen.hpp) searches again in a 4 m window and the lag keeps the long step it found. Measured
// 2026-11-27: the long step 2.19 m off before (largest position error 2.21 m), 0.001 m after
// (0.014 m). The control (the loop with its usual steps only, 17 s) checks the harness; run it
// with
//   build/tests/carmen_test --gtest_filter='LongStep*' --gtest_also_run_disabled_tests
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "channels.hpp"
#include "crafted_logs.hpp"
#include "program.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::carmen::test {
namespace {

namespace fs = std::filesystem;

const std::string kFrontend = std::string(TRAVERSE_BIN_DIR) + "/traverse-frontend";

struct StepRun {
  double long_step_error_m = 0.0;  // the frontend's long step against the true one
  double max_position_error_m = 0.0;
};

// The frontend (configs/frontend.yaml with `extra_yaml` appended) on the crafted loop with one
// 3 m step, its ODOM lines in the log or not; errors of its poses against the log's own (true)
// poses, tied at the first pose.
StepRun run_long_step(const fs::path& dir, bool odometry, const std::string& extra_yaml,
                      double long_step_m = 3.0) {
  CraftedLog log;
  log.poses = loop_path_with_long_step(0.6, long_step_m);
  log.stamps = stamps_fine(static_cast<int>(log.poses.size()), 1.0);
  log.odometry = odometry;
  EXPECT_TRUE(write_log((dir / "in.log").string(), log));
  const std::string carmen_log = (dir / "carmen.lcmlog").string();
  const auto c = run(kCarmen + " " + (dir / "in.log").string() + " --out " + carmen_log);
  EXPECT_EQ(c.exit_code, 0) << c.output;
  {
    std::ifstream shipped("configs/frontend.yaml");
    std::ofstream config(dir / "frontend.yaml");
    config << shipped.rdbuf() << "\n" << extra_yaml << "\n";
  }
  const std::string record = (dir / "frontend.lcmlog").string();
  const auto f = run(kFrontend + " --config " + (dir / "frontend.yaml").string() + " --replay " +
                     carmen_log + " --record " + record);
  EXPECT_EQ(f.exit_code, 0) << f.output;

  const auto est = read_channel<pose2d_t>(record, channels::kPoseFrontend);
  const auto ref = read_channel<pose2d_t>(record, channels::kPoseReference);
  EXPECT_EQ(est.size(), log.poses.size());
  EXPECT_EQ(ref.size(), log.poses.size());
  StepRun r;
  if (est.size() != ref.size() || est.empty()) {
    r.long_step_error_m = r.max_position_error_m = 1e9;
    return r;
  }
  const auto pose = [](const pose2d_t& m) { return Pose2(m.x, m.y, m.theta); };
  const Pose2 T_ref_est = pose(ref.front()) * pose(est.front()).inverse();
  for (std::size_t i = 0; i < est.size(); ++i) {
    EXPECT_EQ(est[i].utime, ref[i].utime);
    const Pose2 e = T_ref_est * pose(est[i]);
    r.max_position_error_m =
        std::max(r.max_position_error_m, (e.translation() - pose(ref[i]).translation()).norm());
    if (i == 0) continue;
    const Pose2 step_ref = between(pose(ref[i - 1]), pose(ref[i]));
    if (step_ref.translation().norm() < 0.99 * long_step_m) continue;
    const Pose2 step_est = between(pose(est[i - 1]), pose(est[i]));
    r.long_step_error_m = (step_est.translation() - step_ref.translation()).norm();
  }
  return r;
}

// The harness itself: the same loop with its usual steps only is followed to centimetres.
TEST(LongStep, DISABLED_ControlWithoutTheLongStep) {
  const auto dir = temp_dir("long-step-control");
  const StepRun r = run_long_step(dir, false, "", 0.6);
  std::printf("0.6 m steps only: largest position error %.3f m\n", r.max_position_error_m);
  EXPECT_LT(r.max_position_error_m, 0.2);
  fs::remove_all(dir);
}

void expect_long_step_followed(bool odometry) {
  const auto dir = temp_dir(odometry ? "long-step-odometry" : "long-step");
  const StepRun r =
      run_long_step(dir, odometry, odometry ? "motion_prior:\n  subsampled_logs: true" : "");
  std::printf("3 m step, %s: the frontend's step off by %.3f m, largest position error %.3f m\n",
              odometry ? "odometry as the prior" : "no odometry", r.long_step_error_m,
              r.max_position_error_m);
  EXPECT_LT(r.long_step_error_m, 0.1);
  EXPECT_LT(r.max_position_error_m, 0.2);
  fs::remove_all(dir);
}

TEST(LongStep, OdometryCarriesTheFrontendOverAThreeMetreStep) { expect_long_step_followed(true); }

TEST(LongStep, AWiderSearchCoversAThreeMetreStepWithoutOdometry) {
  expect_long_step_followed(false);
}

}  // namespace
}  // namespace traverse::carmen::test
