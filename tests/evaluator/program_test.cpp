// The offline program end to end: a small log written here, traverse-evaluator run on it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>

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

// The raw value of `key` in a flat one-line JSON object ("null", a number, or a quoted string).
std::optional<std::string> json_value(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": (\"[^\"]*\"|[^,}]+)"))) {
    return std::nullopt;
  }
  return m[1].str();
}

double json_number(const std::string& json, const std::string& key) {
  const auto v = json_value(json, key);
  if (!v || *v == "null") return std::nan("");
  return std::stod(*v);
}

class EvaluatorProgram : public ::testing::Test {
 protected:
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
    EXPECT_EQ(json_value(r.last_line, key), "0.000000") << key;
  }
  EXPECT_EQ(json_value(r.last_line, "rpe_10m_m"), "null");  // 4 m of travel only
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
  EXPECT_EQ(json_value(r.last_line, "position_rmse_m"), "0.500000");
  EXPECT_EQ(json_value(r.last_line, "position_max_m"), "0.500000");
  EXPECT_EQ(json_value(r.last_line, "position_sd_m"), "0.000000");
  EXPECT_EQ(json_value(r.last_line, "heading_rmse_deg"), "0.572958");  // 0.01 rad
  EXPECT_EQ(json_value(r.last_line, "heading_max_deg"), "0.572958");
  EXPECT_EQ(json_value(r.last_line, "align"), "\"none\"");
}

TEST_F(EvaluatorProgram, FrontendChannelWithOutputs) {
  const fs::path out = dir_ / "out";
  const RunResult r =
      run("--log " + log_ + " --align none --config configs/evaluator.yaml --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.last_line;
  EXPECT_NEAR(json_number(r.last_line, "position_rmse_m"), 0.3, 1e-6);
  EXPECT_EQ(json_number(r.last_line, "matched"), 401);
  EXPECT_EQ(json_value(r.last_line, "estimate_channel"), "\"POSE_FRONTEND\"");
  EXPECT_EQ(json_value(r.last_line, "reference_channel"), "\"POSE_GROUND_TRUTH\"");
  EXPECT_EQ(json_number(r.last_line, "non_finite_poses"), 1);
  EXPECT_EQ(json_number(r.last_line, "decode_failures"), 1);
  // The CSV has a header and one row per matched pose.
  std::ifstream csv(out / "errors.csv");
  std::string header, row;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("utime_us,time_s,travel_m,position_error_m,heading_error_deg,", 0), 0u);
  int rows = 0;
  while (std::getline(csv, row)) ++rows;
  EXPECT_EQ(rows, 401);
  // The plot exists when matplotlib does; the JSON says which.
  const auto png = json_value(r.last_line, "errors_png");
  ASSERT_TRUE(png);
  if (*png != "null") {
    EXPECT_TRUE(fs::exists(out / "errors.png"));
  }
}

TEST_F(EvaluatorProgram, NoMatchIsAFailure) {
  const RunResult r = run("--log " + log_ + " --reference NO_SUCH_CHANNEL");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(json_value(r.last_line, "position_rmse_m"), "null");
  EXPECT_EQ(json_number(r.last_line, "unmatched"), 401);
}

TEST(EvaluatorProgramArgs, BadAlignIsAConfigError) {
  EXPECT_EQ(run("--log configs/evaluator.yaml --align umeyama 2>/dev/null").exit_code, 2);
  EXPECT_EQ(run("--help > /dev/null").exit_code, 0);
}

}  // namespace
}  // namespace traverse::evaluator
