// The frontend swapped at the midpoint of a simulated route (scripts/frontend-swap.sh): the
// swapped run's position RMSE within 20 % of the better of the two frontends alone, and no step
// around the swap off by more than 5 cm.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "graph_test_util.hpp"

namespace traverse::graph_test {
namespace {

// The ICP frontend is the better of the two on this stretch (0.66 against 0.94 mm position
// RMSE): swapped from it to Hector, the swapped run stays within 20 % of it (1.16). Of the twelve
// runs measured (seeds 1 to 3, both directions, ideal and realistic profiles) this one is the
// seventh ratio in order, at the median (0.99 to 1.54): the 20 % holds in 7 of the 12, not in
// all (docs/frontends.md says which and why).
TEST(FrontendSwap, IcpToHectorAtTheMidpointOfASimulatedRoute) {
  const auto r = run("TRAVERSE_BIN_DIR=" + bin_dir() +
                         " scripts/frontend-swap.sh office-s2 --profile ideal --seed 1 "
                         "--duration 40 --from icp --to hector",
                     600);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string json = route_json(r.output);
  const double hector = json_number(json, "hector_alone_rmse_m");
  const double icp = json_number(json, "icp_alone_rmse_m");
  const double swapped = json_number(json, "swapped_rmse_m");
  std::printf("swap: hector %.5f m, icp %.5f m, swapped %.5f m\n", hector, icp, swapped);
  EXPECT_LE(swapped, 1.2 * std::min(hector, icp)) << json;
  EXPECT_LT(json_number(json, "swap_step_error_max_m"), 0.05) << json;
}

}  // namespace
}  // namespace traverse::graph_test

namespace traverse::graph_test {
namespace {

// The operator's command on a live run: the frontend is swapped mid-replay and every scan still
// gets its pose; a kind that does not exist is refused (exit 2), and with no run there the
// command says so (exit 1).
TEST(FrontendSwap, ControlCommandSwapsTheFrontendOfARunningGraph) {
  const auto dir = temp_dir("swap-control");
  const std::string out = (dir / "run").string();
  std::string swapped;
  int swapped_rc = -1;
  std::thread operator_thread([&] {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline &&
           !running_pid(dir / "run" / "processes.json", "logplayer")) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    std::this_thread::sleep_for(std::chrono::seconds(2));
    const auto r = run("TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --out " + out +
                           " --control frontend --kind icp",
                       60);
    swapped = r.output;
    swapped_rc = r.exit_code;
  });
  const auto r = run("TRAVERSE_BIN_DIR=" + bin_dir() +
                         " scripts/run-graph.sh --deploy configs/deploy/pipeline.yaml --stages "
                         "frontend,backend --log logs/office-s2_seed1_20s-22s_profile-every-5th."
                         "lcmlog --grace 1 --speed 0.25 --out " +
                         out,
                     120);
  operator_thread.join();
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(swapped_rc, 0) << swapped;
  EXPECT_NE(swapped.find("\"kind\":\"icp\""), std::string::npos) << swapped;
  const auto counts = count_channels(out + "/run.lcmlog");
  EXPECT_EQ(counts.count("POSE_FRONTEND") ? counts.at("POSE_FRONTEND") : 0, 96);
  EXPECT_GE(counts.count("FRONTEND_CONTROL") ? counts.at("FRONTEND_CONTROL") : 0, 1);
  const std::string control = "TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --out " +
                              out + " --control frontend";
  EXPECT_EQ(run(control + " --kind gmapping", 30).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "run" / "lcm_url"));  // removed when the run ended
  EXPECT_EQ(run(control + " --kind hector", 30).exit_code, 1);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
