// End to end: traverse-validate on logs written here with LogFilePublisher.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "json.hpp"
#include "lcm_log.hpp"
#include "publisher.hpp"
#include "run_program.hpp"
#include "test_messages.hpp"

namespace traverse {
namespace {

namespace fs = std::filesystem;
using test::encode;
using test::run_program;
using traverse::Json;

const std::string kValidate = std::string(TRAVERSE_BIN_DIR) + "/traverse-validate";

// A log writer that can also write bytes that are not a message of their channel's type.
class RawLog : public LogFilePublisher {
 public:
  using LogFilePublisher::LogFilePublisher;
  void raw(const std::string& channel, const std::vector<uint8_t>& bytes, int64_t utime) {
    send(channel, bytes.data(), bytes.size(), utime);
  }
};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class ValidateProgramTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = fs::temp_directory_path() /
            ("traverse_validate_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".lcmlog");
  }
  void TearDown() override { fs::remove(path_); }

  // 20 scans at 10 Hz and a reference pose with each.
  void write_clean(RawLog& log) {
    for (int i = 0; i < 20; ++i) {
      const int64_t t = 1'000'000 + 100'000 * i;
      auto scan = test::make_scan(t, 0, i % 2 ? 181 : 180);
      log.publish("SCAN", scan);
      auto pose = test::make_pose(t, 0);
      log.publish("POSE", pose);
    }
  }

  test::ProgramResult validate(const std::string& options = "") {
    return run_program(kValidate + " " + options + " " + test::quoted(path_.string()));
  }

  fs::path path_;
};

TEST_F(ValidateProgramTest, CleanLogExitsZeroWithCounts) {
  {
    RawLog log(path_.string());
    write_clean(log);
  }
  const auto r = validate();
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const Json j = Json::parse(r.last_line());
  const Json& scan = j["channels"]["SCAN"];
  EXPECT_EQ(scan["type"], "traverse.planar_scan_t");
  EXPECT_EQ(scan["count"], 20);
  EXPECT_EQ(j["channels"]["POSE"]["type"], "traverse.pose2d_t");
  EXPECT_EQ(j["channels"]["POSE"]["count"], 20);
  EXPECT_DOUBLE_EQ(scan["rate_hz"].get<double>(), 10.0);
  EXPECT_DOUBLE_EQ(scan["max_gap_s"].get<double>(), 0.1);
  EXPECT_EQ(scan["backwards"], 0);
  EXPECT_EQ(scan["points_per_scan_min"], 180);
  EXPECT_EQ(scan["points_per_scan_max"], 181);
  EXPECT_EQ(j["events"], 40);
  EXPECT_EQ(j["damage"], Json::array());
  EXPECT_EQ(j["problems"], Json::array());
  EXPECT_EQ(j["ok"], true);
  EXPECT_TRUE(contains(r.out, "log is clean"));
}

TEST_F(ValidateProgramTest, JsonOnlyPrintsOneLine) {
  {
    RawLog log(path_.string());
    write_clean(log);
  }
  const auto r = validate("--json-only");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1);
  EXPECT_EQ(r.out.front(), '{');
}

TEST_F(ValidateProgramTest, LogCutInARecordExitsOneAndNamesTheOffset) {
  {
    RawLog log(path_.string());
    write_clean(log);
  }
  std::vector<LogEvent> events;
  {
    LogReader reader(path_.string());
    while (auto ev = reader.next()) events.push_back(*ev);
  }
  ASSERT_EQ(events.size(), 40u);
  const uint64_t damaged_at = events[30].offset;
  fs::resize_file(path_, damaged_at + 50);  // in the middle of record 30
  const auto r = validate();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const Json j = Json::parse(r.last_line());
  ASSERT_EQ(j["damage"].size(), 1u);
  EXPECT_EQ(j["damage"][0]["offset"], damaged_at);
  EXPECT_EQ(j["events"], 30);  // everything before is still read
  EXPECT_EQ(j["ok"], false);
  EXPECT_TRUE(contains(r.out, "damage at byte " + std::to_string(damaged_at) + ": truncated"));
}

TEST_F(ValidateProgramTest, OtherTypesAndGarbageAreDecodeFailures) {
  {
    RawLog log(path_.string());
    write_clean(log);
    log.raw("POSE", encode(test::make_imu(3'000'000, 0)), 3'000'000);  // an IMU on the pose channel
    log.raw("POSE", {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88}, 3'100'000);
    auto cut = encode(test::make_pose(3'200'000, 20));
    cut.resize(cut.size() / 2);
    log.raw("POSE", cut, 3'200'000);
  }
  const auto r = validate();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const std::string json = r.last_line();
  const Json j = Json::parse(json);
  const Json& pose = j["channels"]["POSE"];
  EXPECT_EQ(pose["type"], "traverse.pose2d_t");
  EXPECT_EQ(pose["count"], 23);
  EXPECT_EQ(pose["decode_failures"], 3);
  EXPECT_EQ(pose["unknown_fingerprint"], 1);
  EXPECT_EQ(pose["undecodable"], 1);
  EXPECT_EQ(pose["other_types"], Json::object({{"traverse.imu_t", 1}}));
  EXPECT_TRUE(contains(json, R"(POSE: 3 of 23 messages do not decode as traverse.pose2d_t)"));
  EXPECT_EQ(j["damage"], Json::array());
}

TEST_F(ValidateProgramTest, TimestampsGoingBackwardsAreReported) {
  {
    RawLog log(path_.string());
    const int64_t times[] = {100, 200, 150, 300};
    for (const int64_t t : times) {
      auto p = test::make_pose(t, 0);
      log.publish("POSE", p);
    }
  }
  const auto r = validate();
  EXPECT_EQ(r.exit_code, 1) << r.out;
  const std::string json = r.last_line();
  const Json j = Json::parse(json);
  const Json& pose = j["channels"]["POSE"];
  EXPECT_EQ(pose["backwards"], 1);
  EXPECT_EQ(pose["event_backwards"], 1);
  EXPECT_EQ(pose["utime_backwards"], 1);
  EXPECT_DOUBLE_EQ(pose["max_backstep_s"].get<double>(), 5e-05);
  EXPECT_TRUE(contains(json, "POSE: timestamps go backwards at 1 messages")) << json;
  EXPECT_TRUE(contains(r.out, "steps back up to 0.000050 s")) << r.out;
}

TEST_F(ValidateProgramTest, EmptyLogIsAProblem) {
  { RawLog log(path_.string()); }
  const auto r = validate();
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(Json::parse(r.last_line())["events"], 0);
}

TEST_F(ValidateProgramTest, HelpAndBadUsage) {
  EXPECT_EQ(run_program(kValidate + " --help").exit_code, 0);
  EXPECT_EQ(run_program(kValidate).exit_code, 2);
  EXPECT_EQ(run_program(kValidate + " /nonexistent/traverse.lcmlog").exit_code, 2);
  EXPECT_EQ(run_program(kValidate + " " + fs::temp_directory_path().string()).exit_code, 2);
  EXPECT_EQ(run_program(kValidate + " --no-such-option x").exit_code, 2);
}

}  // namespace
}  // namespace traverse
