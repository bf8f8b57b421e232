// The harness of the offline program's tests (program_*_test.cpp): traverse-evaluator run on a
// small log written by each test, its one-line JSON and CSV rows read back, and a fixture whose
// log holds 10 s of ground truth and a frontend 0.3 m off.
#pragma once

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

namespace fs = std::filesystem;

struct RunResult {
  int exit_code = -1;
  std::string last_line;
};

inline RunResult run(const std::string& args) {
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
inline Json json_value(const std::string& json, const std::string& key) {
  const Json j = Json::parse(json, nullptr, false);
  return !j.is_discarded() && j.is_object() && j.contains(key) ? j[key] : Json();
}

inline double json_number(const std::string& json, const std::string& key) {
  const Json v = json_value(json, key);
  return v.is_number() ? v.get<double>() : std::nan("");
}

// The field of a CSV row under `name` in its header (our CSVs quote nothing); "?" when absent.
inline std::string csv_field(const std::string& header, const std::string& row, const std::string& name) {
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

}  // namespace traverse::evaluator
