// The offline program end to end on a pose2d_t estimate: figures, outputs, refusals, arguments.
#include "program_harness.hpp"

namespace traverse::evaluator {
namespace {

TEST_F(EvaluatorProgram, GroundTruthAgainstItselfIsZero) {
  const RunResult r = run("--log " + log_ + " --estimate POSE_GROUND_TRUTH");
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  for (const char* key : {"position_rmse_m", "position_sd_m", "position_max_m", "heading_rmse_deg",
                          "heading_sd_deg", "heading_max_deg", "rpe_1m_m", "max_jump_m"}) {
    EXPECT_DOUBLE_EQ(json_number(r.last_line, key), 0.0) << key;
  }
  EXPECT_TRUE(json_value(r.last_line, "rpe_10m_m").is_null());  // 4 m of travel only
  EXPECT_EQ(json_number(r.last_line, "matched"), 2001);
  EXPECT_EQ(json_number(r.last_line, "unmatched"), 0);
  EXPECT_NEAR(json_number(r.last_line, "duration_s"), 10.0, 1e-9);
  EXPECT_NEAR(json_number(r.last_line, "length_m"), 4.0, 1e-3);
}

TEST_F(EvaluatorProgram, ShiftedGroundTruthShowsTheShift) {
  const RunResult r = run("--log " + log_ +
                          " --estimate POSE_GROUND_TRUTH --align none --shift-estimate 0.3 -0.4 "
                          "0.01");
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "position_rmse_m"), 0.5);
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "position_max_m"), 0.5);
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "position_sd_m"), 0.0);
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "heading_rmse_deg"), 0.572958);  // 0.01 rad
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "heading_max_deg"), 0.572958);
  EXPECT_EQ(json_value(r.last_line, "align"), "none");
}

TEST_F(EvaluatorProgram, FrontendChannelWithOutputs) {
  const fs::path out = dir_ / "out";
  const RunResult r =
      run("--log " + log_ + " --align none --config configs/evaluator.yaml --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  EXPECT_NEAR(json_number(r.last_line, "position_rmse_m"), 0.3, 1e-6);
  EXPECT_EQ(json_number(r.last_line, "matched"), 401);
  EXPECT_EQ(json_value(r.last_line, "estimate_channel"), "POSE_FRONTEND");
  EXPECT_EQ(json_value(r.last_line, "reference_channel"), "POSE_GROUND_TRUTH");
  EXPECT_EQ(json_number(r.last_line, "non_finite_poses"), 1);
  // The imu_t on the pose2d_t channel: a second type on one channel, counted and dropped.
  EXPECT_EQ(json_number(r.last_line, "mixed_type_messages"), 1);
  EXPECT_EQ(json_number(r.last_line, "decode_failures"), 0);
  EXPECT_EQ(json_value(r.last_line, "estimate_type"), "pose2d_t");
  // No backend in this log: no closure, and the closure figures say so.
  EXPECT_EQ(json_number(r.last_line, "loop_closures"), 0);
  EXPECT_EQ(json_number(r.last_line, "false_loop_closures"), 0);
  EXPECT_EQ(json_number(r.last_line, "loop_closures_unmatched"), 0);
  EXPECT_TRUE(json_value(r.last_line, "loop_closure_max_mahalanobis").is_null());
  EXPECT_TRUE(json_value(r.last_line, "loop_closure_rms_error_m").is_null());
  EXPECT_TRUE(fs::exists(out / "closures.csv"));
  // The CSV has a header and one row per matched pose.
  std::ifstream csv(out / "errors.csv");
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("utime_us,time_s,travel_m,position_error_m,heading_error_deg,", 0), 0u);
  int rows = 0;
  while (std::getline(csv, row)) ++rows;
  EXPECT_EQ(rows, 401);
  // The plot exists when matplotlib does; the JSON says which.
  ASSERT_TRUE(Json::parse(r.last_line).contains("errors_png")) << r.last_line;
  if (!json_value(r.last_line, "errors_png").is_null()) {
    EXPECT_TRUE(fs::exists(out / "errors.png"));
  }
}

TEST_F(EvaluatorProgram, NoMatchIsAFailure) {
  const RunResult r = run("--log " + log_ + " --reference NO_SUCH_CHANNEL");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(json_value(r.last_line, "position_rmse_m").is_null());
  EXPECT_EQ(json_number(r.last_line, "unmatched"), 401);
}

// The "perfect run": a log of 237 scans whose stamps carried no time, a backend that
// published a single key pose. One reference pose of 237 covered: refused, not RMSE 0.
TEST(EvaluatorProgramCoverage, ASinglePoseIsAFailureNotAPerfectRun) {
  const fs::path dir =
      fs::temp_directory_path() / ("traverse_evaluator_coverage_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string log = (dir / "run.lcmlog").string();
  {
    LogFilePublisher out(log);
    for (int i = 0; i < 237; ++i) {
      pose2d_t ref{};
      ref.utime = 3'000'000 * (i + 1);
      ref.x = 0.5 * i;
      out.publish("POSE_REFERENCE", ref);
      if (i == 0) out.publish("POSE_BACKEND", ref);
    }
  }
  const RunResult r = run("--log " + log + " --estimate POSE_BACKEND --reference POSE_REFERENCE");
  EXPECT_EQ(r.exit_code, 1) << r.last_line;
  EXPECT_EQ(json_number(r.last_line, "matched"), 1);
  EXPECT_EQ(json_number(r.last_line, "reference_covered"), 1);
  EXPECT_NEAR(json_number(r.last_line, "reference_share"), 1.0 / 237, 1e-4);
  EXPECT_EQ(json_value(r.last_line, "refused"), true);
  EXPECT_TRUE(json_value(r.last_line, "position_rmse_m").is_null());
  EXPECT_TRUE(json_value(r.last_line, "max_jump_m").is_null());
  fs::remove_all(dir);
}

TEST_F(EvaluatorProgram, PartialCoverageIsRefusedFullIsNot) {
  // The frontend's poses cover all 10 s of truth: scored.
  const RunResult full = run("--log " + log_);
  EXPECT_EQ(full.exit_code, 0) << full.last_line;
  EXPECT_EQ(json_value(full.last_line, "refused"), false);
  EXPECT_NEAR(json_number(full.last_line, "reference_share"), 1.0, 1e-3);
  EXPECT_EQ(json_number(full.last_line, "min_reference_share"), 0.8);
  // A stage that stopped after 7 s: 70 % of the truth, refused by default, scored at 0.6.
  const std::string partial = (dir_ / "partial.lcmlog").string();
  {
    LogFilePublisher out(partial);
    for (const StampedPose& p : test::circle_truth(10)) {
      pose2d_t msg{};
      msg.utime = p.utime;
      msg.x = p.pose.x();
      msg.y = p.pose.y();
      msg.theta = p.pose.theta();
      out.publish("POSE_GROUND_TRUTH", msg);
      if (p.utime <= 7'800'000) out.publish("POSE_FRONTEND", msg);
    }
  }
  const RunResult refused = run("--log " + partial + " 2>/dev/null");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_EQ(json_value(refused.last_line, "refused"), true);
  EXPECT_NEAR(json_number(refused.last_line, "reference_share"), 0.68, 0.01);
  const fs::path cfg = dir_ / "share.yaml";
  std::ofstream(cfg) << "min_reference_share: 0.6\n";
  const RunResult lenient = run("--log " + partial + " --config " + cfg.string());
  EXPECT_EQ(lenient.exit_code, 0) << lenient.last_line;
  EXPECT_DOUBLE_EQ(json_number(lenient.last_line, "position_max_m"), 0.0);
}

TEST(EvaluatorProgramArgs, BadAlignIsAConfigError) {
  EXPECT_EQ(run("--log configs/evaluator.yaml --align umeyama 2>/dev/null").exit_code, 2);
  EXPECT_EQ(run("--help > /dev/null").exit_code, 0);
  const fs::path cfg = fs::temp_directory_path() /
                       ("traverse_evaluator_sigmas_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(cfg) << "false_closure_sigmas: -1\n";
  EXPECT_EQ(run("--log configs/evaluator.yaml --config " + cfg.string() + " 2>/dev/null").exit_code,
            2);
  fs::remove(cfg);
}

}  // namespace
}  // namespace traverse::evaluator
