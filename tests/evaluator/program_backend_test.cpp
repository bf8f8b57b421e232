// The offline program on the backend's outputs: key poses (final revision, loop closures) and the
// densifier's segments (newest revision), and mixed types on the estimate channel.
#include "program_harness.hpp"

namespace traverse::evaluator {
namespace {

// The ground truth of test::circle_truth(10) on POSE_GROUND_TRUTH.
void publish_truth(LogFilePublisher& out) {
  for (const StampedPose& p : test::circle_truth(10)) {
    pose2d_t msg = test::pose_message(p);
    out.publish("POSE_GROUND_TRUTH", msg);
  }
}

// Ground truth for 1..11 s and the backend's incremental key poses: a first estimate 0.5 m off,
// then an optimisation that moves every key pose onto the truth, with loop closures.
void write_key_poses_log(const std::string& path) {
  LogFilePublisher out(path);
  publish_truth(out);
  using test::key_pose;
  using test::loop_closure;
  const std::vector<int64_t> t_us = {1'500'000, 3'000'000, 5'000'000, 7'000'000, 9'000'000};
  std::vector<key_pose_t> first, revised;
  for (int i = 0; i < 5; ++i) {
    first.push_back(key_pose(i, t_us[i], 0.5));
    revised.push_back(key_pose(i, t_us[i]));
  }
  revised.push_back(key_pose(5, 10'000'000));
  auto m1 = test::key_poses(1, first);
  out.publish("KEY_POSES", m1);
  auto m2 = test::key_poses(
      2, revised,
      {loop_closure(0, 5, t_us[0], 10'000'000, Pose2()),  // exact
                                                          // 6 sigma off in x (sigma 0.01 m): false
       loop_closure(1, 4, t_us[1], t_us[4], Pose2(0.06, 0.0, 0.0)),
       // from 0.5 s, before the ground truth starts: unmatched
       loop_closure(7, 4, 500'000, t_us[4], Pose2())});
  out.publish("KEY_POSES", m2);
  // The exact closure once more (a resend): counted once.
  auto m3 = test::key_poses(3, {}, {loop_closure(0, 5, t_us[0], 10'000'000, Pose2())});
  out.publish("KEY_POSES", m3);
}

TEST_F(EvaluatorProgram, KeyPosesFinalTrajectoryAndLoopClosures) {
  const std::string log = (dir_ / "backend.lcmlog").string();
  write_key_poses_log(log);
  const fs::path out = dir_ / "out";
  const RunResult r =
      run("--log " + log + " --estimate KEY_POSES --align none --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  EXPECT_EQ(json_value(r.last_line, "estimate_type"), "key_poses_t");
  EXPECT_EQ(json_number(r.last_line, "estimate_poses"), 6);
  EXPECT_EQ(json_number(r.last_line, "key_pose_revisions"), 5);
  // The revisions replaced the first estimates, 0.5 m off.
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "position_max_m"), 0.0);
  EXPECT_EQ(json_number(r.last_line, "loop_closures"), 3);
  EXPECT_EQ(json_number(r.last_line, "false_loop_closures"), 1);
  EXPECT_EQ(json_number(r.last_line, "loop_closures_unmatched"), 1);
  EXPECT_NEAR(json_number(r.last_line, "loop_closure_max_mahalanobis"), 6.0, 1e-3);
  EXPECT_NEAR(json_number(r.last_line, "loop_closure_max_error_m"), 0.06, 1e-6);
  EXPECT_NEAR(json_number(r.last_line, "loop_closure_rms_error_m"), 0.06 / std::sqrt(2.0), 1e-6);
  EXPECT_EQ(json_number(r.last_line, "mixed_type_messages"), 0);
  // closures.csv: a header and one row per distinct closure, the false one flagged.
  std::ifstream csv(out / "closures.csv");
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("from_id,to_id,from_utime_us,to_utime_us,matched,", 0), 0u);
  std::vector<std::string> rows;
  while (std::getline(csv, row)) rows.push_back(row);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].rfind("0,5,", 0), 0u);
  EXPECT_EQ(csv_field(header, rows[0], "false"), "0");
  EXPECT_EQ(rows[1].rfind("1,4,", 0), 0u);
  EXPECT_EQ(csv_field(header, rows[1], "false"), "1");
  // Against a reference the frontend's own error is not known: empty, not zero.
  EXPECT_EQ(csv_field(header, rows[1], "frontend_err_xy_m"), "");
  EXPECT_EQ(rows[2].rfind("7,4,500000,9000000,0,", 0), 0u);
  // The same log, another estimate: the closures are checked whatever stage is evaluated, and
  // the threshold is the config's.
  const fs::path cfg = dir_ / "seven.yaml";
  std::ofstream(cfg) << "false_closure_sigmas: 7\n";
  const RunResult seven =
      run("--log " + log + " --estimate POSE_GROUND_TRUTH --config " + cfg.string());
  ASSERT_EQ(seven.exit_code, 0) << seven.last_line;
  EXPECT_EQ(json_number(seven.last_line, "loop_closures"), 3);
  EXPECT_EQ(json_number(seven.last_line, "false_loop_closures"), 0);
}

TEST_F(EvaluatorProgram, DenseSegmentsNewestRevision) {
  const std::string log = (dir_ / "dense.lcmlog").string();
  {
    LogFilePublisher out(log);
    publish_truth(out);
    using test::dense_segment;
    auto m1 = test::dense_segments(
        {dense_segment(0, 0, 1'000'000, 0.3), dense_segment(1, 0, 2'000'000, 0.3)});
    auto m2 = test::dense_segments({dense_segment(0, 1, 1'000'000, 0.0),
                                    dense_segment(1, 1, 2'000'000, 0.0),
                                    dense_segment(2, 0, 3'000'000, 0.0)});
    auto m3 = test::dense_segments({dense_segment(1, 0, 2'000'000, 0.3)});  // stale, late
    out.publish("DENSE_SEGMENTS", m1);
    out.publish("DENSE_SEGMENTS", m2);
    out.publish("DENSE_SEGMENTS", m3);
  }
  // Three segments cover 3 s of the 10 s of truth: scored all the same (min_reference_share 0).
  const RunResult r = run("--log " + log + " --estimate DENSE_SEGMENTS --align none --config " +
                          any_share_config());
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  EXPECT_EQ(json_value(r.last_line, "estimate_type"), "dense_segments_t");
  EXPECT_EQ(json_number(r.last_line, "dense_segments"), 3);
  EXPECT_EQ(json_number(r.last_line, "estimate_poses"), 3 * 21 - 2);  // shared ends once
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "position_max_m"), 0.0);
  EXPECT_EQ(json_number(r.last_line, "loop_closures"), 0);
}

TEST_F(EvaluatorProgram, MixedTypesOnTheEstimateChannelAreReported) {
  const std::string mixed = (dir_ / "mixed.lcmlog").string();
  {
    LogFilePublisher out(mixed);
    publish_truth(out);
    auto k = test::key_poses(1, {test::key_pose(0, 2'000'000), test::key_pose(1, 4'000'000)});
    out.publish("KEY_POSES", k);
    pose2d_t stray{};  // a pose2d_t publisher on the key poses' channel
    stray.utime = 5'000'000;
    out.publish("KEY_POSES", stray);
    out.publish("KEY_POSES", stray);
  }
  const RunResult r = run("--log " + mixed + " --estimate KEY_POSES --align none --config " +
                          any_share_config() + " 2>/dev/null");
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  EXPECT_EQ(json_value(r.last_line, "estimate_type"), "key_poses_t");
  EXPECT_EQ(json_number(r.last_line, "mixed_type_messages"), 2);
  EXPECT_EQ(json_number(r.last_line, "estimate_poses"), 2);
  EXPECT_DOUBLE_EQ(json_number(r.last_line, "position_max_m"), 0.0);
}

}  // namespace
}  // namespace traverse::evaluator
