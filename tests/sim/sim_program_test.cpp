// Runs the built traverse-sim program: same inputs, profile and seed give byte-identical logs.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>

#include "bus.hpp"
#include "traverse/pose2d_t.hpp"
#include "traverse/process_status_t.hpp"

namespace {

std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

int run(const std::string& args) {
  const std::string cmd =
      std::string(TRAVERSE_BIN_DIR) + "/traverse-sim " + args + " > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("traverse_sim_test_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

TEST(SimProgram, SameSeedGivesIdenticalLogsAndAnotherSeedDiffers) {
  const std::string base =
      "--world configs/worlds/office.yaml --route configs/routes/office-s2.yaml --begin 20 "
      "--duration 0.5 ";
  const std::string a = temp_path("a.lcmlog"), b = temp_path("b.lcmlog"), c = temp_path("c.lcmlog");
  ASSERT_EQ(run(base + "--seed 1 --out " + a), 0);
  ASSERT_EQ(run(base + "--seed 1 --out " + b), 0);
  ASSERT_EQ(run(base + "--seed 2 --out " + c), 0);
  const std::string da = read_all(a), db = read_all(b), dc = read_all(c);
  EXPECT_GT(da.size(), 1000000u);
  EXPECT_TRUE(da == db);
  EXPECT_EQ(da.size(), dc.size());
  EXPECT_FALSE(da == dc);
  // The ideal profile is as deterministic, and a different log.
  const std::string d = temp_path("d.lcmlog"), e = temp_path("e.lcmlog");
  ASSERT_EQ(run(base + "--seed 1 --profile ideal --out " + d), 0);
  ASSERT_EQ(run(base + "--seed 1 --profile ideal --out " + e), 0);
  EXPECT_TRUE(read_all(d) == read_all(e));
  EXPECT_FALSE(read_all(d) == da);
  EXPECT_EQ(run(base + "--profile nope --out " + e), 2);  // a profile that does not exist
  for (const auto& p : {a, b, c, d, e}) std::filesystem::remove(p);
}

TEST(SimProgram, HelpAndBadInputs) {
  EXPECT_EQ(run("--help"), 0);
  EXPECT_EQ(
      run("--world configs/worlds/nope.yaml --route configs/routes/office-s2.yaml --out /dev/null"),
      2);
  // A route for another world is refused.
  EXPECT_EQ(run("--world configs/worlds/court.yaml --route configs/routes/office-s2.yaml --out "
                "/dev/null"),
            2);
}

// Without --out the program publishes live at the sensors' pace, with its status once a second.
TEST(SimProgram, PublishesLiveAtTheSensorsPace) {
  const std::string url = "udpm://239.255.76.67:7794?ttl=0&recv_buf_size=8388608";
  traverse::Bus bus(url);
  if (!bus.good()) GTEST_SKIP() << "no multicast on this host";
  int poses = 0, statuses = 0;
  bus.subscribe<traverse::pose2d_t>("POSE_GROUND_TRUTH",
                                    [&](const traverse::pose2d_t&) { ++poses; });
  bus.subscribe<traverse::process_status_t>("STATUS_SIM",
                                            [&](const traverse::process_status_t&) { ++statuses; });
  std::atomic<int> rc{-1};
  std::thread child([&] {
    rc =
        run("--world configs/worlds/corridor.yaml --route configs/routes/corridor-return.yaml "
            "--seed 1 --begin 10 --duration 0.5 --speed 1 --lcm-url '" +
            url + "'");
  });
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (rc < 0 && std::chrono::steady_clock::now() < until) bus.handle(50);
  child.join();
  for (int i = 0; i < 5; ++i) bus.handle(20);
  EXPECT_EQ(rc, 0);
  EXPECT_GE(poses, 95);  // 0.5 s at 200 Hz: 101 poses, allowing for a lost datagram or two
  EXPECT_LE(poses, 101);
  EXPECT_GE(statuses, 1);
}

}  // namespace
