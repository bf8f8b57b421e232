// scripts/eval-kummerle.sh end to end on a crafted log with its relations: the driver, the
// frontend offline, the relations scoring; the last line's JSON names what was scored. A log
// whose frontend publishes a single pose fails the run (it would score as perfect otherwise).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "crafted_logs.hpp"
#include "program.hpp"

namespace traverse::carmen::test {
namespace {

namespace fs = std::filesystem;

std::optional<std::string> json_value(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": (\"[^\"]*\"|[^,}]+)"))) {
    return std::nullopt;
  }
  return m[1].str();
}

class EvalKummerle : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = temp_dir("eval-kummerle"); }
  void TearDown() override {
    fs::remove_all(dir_);
    if (fs::exists("out/eval")) {
      for (const auto& e : fs::directory_iterator("out/eval")) {
        if (e.path().filename().string().rfind("kummerle-" + name_, 0) == 0) fs::remove_all(e);
      }
    }
    for (const char* ext : {".lcmlog", ".lcmlog.json", ".lcmlog.out"}) {
      fs::remove("out/cache/kummerle-" + name_ + ext);
    }
  }
  // The script on a log: its output (last line JSON) and exit code.
  Result eval(const CraftedLog& log, const std::string& stages) {
    const auto path = dir_ / (name_ + ".log");
    EXPECT_TRUE(write_log(path.string(), log));
    EXPECT_TRUE(write_relations((dir_ / (name_ + ".relations")).string(), log, 5));
    return run("env TRAVERSE_BIN_DIR=" + std::string(TRAVERSE_BIN_DIR) +
               " scripts/eval-kummerle.sh " + path.string() + " --stages " + stages + " --offline");
  }

  fs::path dir_;
  const std::string name_ = "crafted" + std::to_string(getpid());
};

TEST_F(EvalKummerle, ScoresTheFrontendByTheRelations) {
  CraftedLog log;
  log.poses = loop_path(0.1);
  log.stamps = stamps_fine(static_cast<int>(log.poses.size()), 0.1);
  const Result r = eval(log, "frontend");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = last_line(r.output);
  std::printf("%s\n", json.substr(0, 600).c_str());
  const std::size_t relations = log.poses.size() - 5;
  EXPECT_EQ(json_value(json, "relations_used"), std::to_string(relations)) << json;
  EXPECT_EQ(json_value(json, "channel"), "\"POSE_FRONTEND\"");
  const auto scored = json_value(json, "scored_log");
  ASSERT_TRUE(scored);
  EXPECT_TRUE(fs::exists(scored->substr(1, scored->size() - 2)));
  // A clean room scanned without noise: centimetres at most.
  EXPECT_LT(std::stod(*json_value(json, "trans_mean_m")), 0.05) << json;
  EXPECT_LT(std::stod(*json_value(json, "rot_mean_deg")), 1.0) << json;
  EXPECT_GT(std::stod(*json_value(json, "wall_s")), 0.0);
  EXPECT_NEAR(std::stod(*json_value(json, "log_s")), 0.1 * (log.poses.size() - 1), 1e-3);
}

TEST_F(EvalKummerle, AStageWithASinglePoseFailsTheRun) {
  CraftedLog log;
  log.poses = {loop_path(0.1).front()};
  log.stamps = stamps_fine(1, 0.1);
  const Result r = eval(log, "frontend");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("stage frontend published 1 pose(s) on POSE_FRONTEND"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace traverse::carmen::test
