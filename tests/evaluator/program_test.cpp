// The offline program end to end: a small log written here, traverse-evaluator run on it.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "json.hpp"
#include "messages.hpp"
#include "publisher.hpp"
#include "synthetic.hpp"
#include "traverse/imu_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::evaluator {
namespace {

namespace fs = std::filesystem;

struct RunResult {
  int exit_code = -1;
  std::string last_line;
};

RunResult run(const std::string& args) {
  const std::string cmd = std::string(TRAVERSE_BIN_DIR) + "/traverse-evaluator " + args;
  FILE* pipe = popen(cmd.c_str(), "r");
  RunResult r;
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  std::string line;
  while (std::fgets(buf.data(), buf.size(), pipe)) {
    line += buf.data();
    if (!line.empty() && line.back() == '\n') {
      line.pop_back();
      if (!line.empty()) r.last_line = line;
      line.clear();
    }
  }
  if (!line.empty()) r.last_line = line;
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The value of `key` in the program's one-line JSON summary (null when absent or not JSON).
Json json_value(const std::string& json, const std::string& key) {
  const Json j = Json::parse(json, nullptr, false);
  return !j.is_discarded() && j.is_object() && j.contains(key) ? j[key] : Json();
}

double json_number(const std::string& json, const std::string& key) {
  const Json v = json_value(json, key);
  return v.is_number() ? v.get<double>() : std::nan("");
}

// The field of a CSV row under `name` in its header (our CSVs quote nothing); "?" when absent.
std::string csv_field(const std::string& header, const std::string& row, const std::string& name) {
  const auto split = [](const std::string& line) {
    std::vector<std::string> fields(1);
    for (const char ch : line) {
      if (ch == ',') {
        fields.emplace_back();
      } else {
        fields.back() += ch;
      }
    }
    return fields;
  };
  const std::vector<std::string> names = split(header), values = split(row);
  for (std::size_t i = 0; i < names.size() && i < values.size(); ++i) {
    if (names[i] == name) return values[i];
  }
  return "?";
}

class EvaluatorProgram : public ::testing::Test {
 protected:
  // A config that scores an estimate however little of the reference it covers.
  std::string any_share_config() const {
    const fs::path cfg = dir_ / "any-share.yaml";
    std::ofstream(cfg) << "min_reference_share: 0.0\n";
    return cfg.string();
  }

  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("traverse_evaluator_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    log_ = (dir_ / "run.lcmlog").string();
    // 10 s of ground truth at 200 Hz and a frontend at 40 Hz that is 0.3 m off in x.
    LogFilePublisher out(log_);
    for (const StampedPose& p : test::circle_truth(10)) {
      pose2d_t msg{};
      msg.utime = p.utime;
      msg.parent_frame = "world";
      msg.child_frame = "base";
      msg.x = p.pose.x();
      msg.y = p.pose.y();
      msg.theta = p.pose.theta();
      out.publish("POSE_GROUND_TRUTH", msg);
      if ((p.utime / 5'000) % 5 == 0) {
        msg.x += 0.3;
        out.publish("POSE_FRONTEND", msg);
      }
    }
    // A broken pose and a message of another type on the frontend's channel: both left out.
    pose2d_t broken{};
    broken.utime = 2'000'001;
    broken.x = std::nan("");
    out.publish("POSE_FRONTEND", broken);
    imu_t imu{};
    imu.utime = 2'000'002;
    out.publish("POSE_FRONTEND", imu);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string log_;
};

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

// --relations on a log: relations between scans 1 s apart, each 2 cm longer in x than the truth
// (relations_test.cpp checks the metric on varied errors; this checks the program: channels,
// counts, keys, CSV, exit codes).
TEST_F(EvaluatorProgram, RelationsModeScoresTheEstimateChannel) {
  const fs::path rel = dir_ / "run.relations";
  {
    std::ofstream out(rel);
    const auto truth = test::circle_truth(10);
    for (std::size_t i = 0; i + 200 < truth.size(); i += 25) {  // frontend scans, 1 s apart
      const Pose2 d = between(truth[i].pose, truth[i + 200].pose);
      out << fmt::format("{}.{:06d} {}.{:06d} {:.9f} {:.9f} 0 0 0 {:.9f}\n",
                         truth[i].utime / 1'000'000, truth[i].utime % 1'000'000,
                         truth[i + 200].utime / 1'000'000, truth[i + 200].utime % 1'000'000,
                         d.x() + 0.02, d.y(), d.theta());
    }
    out << "1.000000 999.000000 0 0 0 0 0 0\n";  // a stamp no scan has: missing
  }
  const RunResult truth = run("--log " + log_ + " --estimate POSE_GROUND_TRUTH --relations " +
                              rel.string() + " --out " + (dir_ / "out").string());
  ASSERT_EQ(truth.exit_code, 0) << truth.last_line;
  EXPECT_EQ(json_value(truth.last_line, "mode"), "relations");
  EXPECT_EQ(json_number(truth.last_line, "relations"), 74);
  EXPECT_EQ(json_number(truth.last_line, "relations_used"), 73);
  EXPECT_EQ(json_number(truth.last_line, "relations_missing"), 1);
  // Every relation 2 cm longer in x than the truth: 0.02 m back, the same for all.
  EXPECT_NEAR(json_number(truth.last_line, "trans_mean_m"), 0.02, 2e-6);
  EXPECT_NEAR(json_number(truth.last_line, "trans_sd_m"), 0.0, 2e-6);
  EXPECT_NEAR(json_number(truth.last_line, "trans_sq_mean_m2"), 4e-4, 1e-7);
  EXPECT_NEAR(json_number(truth.last_line, "rot_mean_deg"), 0.0, 1e-6);
  EXPECT_EQ(json_value(truth.last_line, "estimate_channel"), "POSE_GROUND_TRUTH");
  std::ifstream csv(dir_ / "out" / "relations.csv");
  int rows = -1;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 74);
  // No loop closure on this log: none checked, figures null; the frontend's error over a bridge
  // is still measured by the 73 short relations, each 2 cm off in x: sqrt(0.02^2 / 2) m, with x
  // and y made isotropic.
  EXPECT_EQ(json_number(truth.last_line, "closures"), 0);
  EXPECT_EQ(json_number(truth.last_line, "checked"), 0);
  EXPECT_TRUE(json_value(truth.last_line, "median_sigmas").is_null());
  EXPECT_TRUE(json_value(truth.last_line, "closure_nearer").is_null());
  EXPECT_EQ(json_value(truth.last_line, "frontend_channel"), "POSE_FRONTEND");
  EXPECT_EQ(json_number(truth.last_line, "frontend_poses"), 401);  // every 25th, NaN left out
  EXPECT_NEAR(json_number(truth.last_line, "bridge_sigma_m"), 0.0141, 1e-9);
  EXPECT_NEAR(json_number(truth.last_line, "bridge_sigma_deg"), 0.0, 1e-9);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "closures.csv"));
  // The frontend channel (every 25th truth pose, all 0.3 m off in x: a shift of the whole
  // trajectory, which no relative pose sees): the same relations, the same errors.
  const RunResult frontend = run("--log " + log_ + " --relations " + rel.string());
  EXPECT_EQ(frontend.exit_code, 0) << frontend.last_line;
  EXPECT_EQ(json_number(frontend.last_line, "relations_used"), 73);
  EXPECT_NEAR(json_number(frontend.last_line, "trans_mean_m"), 0.02, 2e-6);
  // A channel with nothing on it: refused, exit 1, figures null.
  const RunResult none =
      run("--log " + log_ + " --estimate POSE_DENSE --relations " + rel.string() + " 2>/dev/null");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_EQ(json_value(none.last_line, "refused"), true);
  EXPECT_TRUE(json_value(none.last_line, "trans_mean_m").is_null());
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
