// End to end: traverse-monitor listening on a private udpm port, stopped by SIGINT, writes its
// summary with what it heard.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "bus.hpp"
#include "json.hpp"
#include "run_program.hpp"
#include "test_messages.hpp"
#include "traverse/process_status_t.hpp"

namespace traverse {
namespace {

namespace fs = std::filesystem;

const std::string kMonitor = std::string(TRAVERSE_BIN_DIR) + "/traverse-monitor";
// A port of its own per test process, so that test runs at the same time do not hear each other.
std::string private_url() {
  return "udpm://239.255.76.67:" + std::to_string(40000 + ::getpid() % 20000) + "?ttl=0";
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Handles messages until `done()` or the deadline; true if done.
template <class F>
bool handle_until(Bus& bus, F done, std::chrono::seconds deadline) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    bus.handle(50);
  }
  return true;
}

TEST(MonitorProgram, HelpAndUnknownConfigKey) {
  EXPECT_EQ(test::run_program(kMonitor + " --help").exit_code, 0);
  const fs::path cfg =
      fs::temp_directory_path() / ("traverse_monitor_bad_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(cfg) << "status_timeout: 2\n";
  EXPECT_EQ(test::run_program(kMonitor + " --config " + cfg.string()).exit_code, 2);
  fs::remove(cfg);
}

TEST(MonitorProgram, WritesWhatItHeardAtShutdown) {
  const std::string tag = std::to_string(::getpid());
  const fs::path out = fs::temp_directory_path() / ("traverse_monitor_" + tag + ".json");
  const fs::path stdout_path = fs::temp_directory_path() / ("traverse_monitor_" + tag + ".out");
  const std::string cfg_path = "configs/monitor.yaml";

  const std::string url = private_url();
  Bus bus(url);
  ASSERT_TRUE(bus.good());
  int statuses = 0;
  bus.subscribe<process_status_t>("STATUS_MONITOR_TEST",
                                  [&](const process_status_t&) { ++statuses; });

  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    std::freopen(stdout_path.c_str(), "w", stdout);
    execl(kMonitor.c_str(), kMonitor.c_str(), "--lcm-url", url.c_str(), "--name", "monitor_test",
          "--config", cfg_path.c_str(), "--out", out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Listening once its first status is heard.
  const bool up = handle_until(
      bus, [&] { return statuses >= 1; }, std::chrono::seconds(10));
  if (up) {
    for (int i = 0; i < 5; ++i) {
      auto pose = test::make_pose(1000 * (i + 1), 0);
      bus.publish("POSE_MONITOR_TEST", pose);
    }
    // Two more statuses: the poses have certainly been handled.
    handle_until(
        bus, [&] { return statuses >= 3; }, std::chrono::seconds(10));
  }
  kill(pid, SIGINT);
  int wstatus = 0;
  waitpid(pid, &wstatus, 0);
  ASSERT_TRUE(up) << "no status from traverse-monitor";
  EXPECT_TRUE(WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0);

  const std::string json = read_file(out);
  const Json j = Json::parse(json);
  EXPECT_EQ(j["channels"]["POSE_MONITOR_TEST"]["type"], "traverse.pose2d_t") << json;
  EXPECT_EQ(j["channels"]["POSE_MONITOR_TEST"]["count"], 5) << json;
  EXPECT_EQ(j["processes"]["monitor_test"]["channel"], "STATUS_MONITOR_TEST") << json;
  EXPECT_EQ(j["processes"]["monitor_test"]["state"], "running") << json;
  // The same JSON is the last line of its standard output.
  EXPECT_NE(read_file(stdout_path).find(json), std::string::npos);
  fs::remove(out);
  fs::remove(stdout_path);
}

}  // namespace
}  // namespace traverse
