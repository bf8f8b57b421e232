// Crash recovery (docs/deployment.md): the backend SIGKILLed mid-run is restarted by the launcher
// on its state directory, resumes its graph and key scans, and the run's products match an
// undisturbed run's: at most the key poses of the time it was down (and since its last snapshot)
// missing, and the final key poses' and dense trajectory's RMSE against ground truth within 2 mm
// of the undisturbed run's. The run log stays whole.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <thread>

#include "graph_test_util.hpp"
#include "lcm_log.hpp"
#include "traverse/key_poses_t.hpp"

namespace traverse::graph_test {
namespace {

// The number of key poses of a recorded run (the last KEY_POSES message's count).
int32_t key_pose_count(const std::string& log) {
  int32_t total = 0;
  LogReader reader(log);
  while (auto ev = reader.next()) {
    key_poses_t m;
    if (ev->channel == "KEY_POSES" &&
        m.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) > 0) {
      total = m.total_key_poses;
    }
  }
  return total;
}

TEST(CrashRecovery, BackendKilledMidRunIsRestartedAndResumesItsGraph) {
  const auto dir = temp_dir("crash");
  const std::string sim = (dir / "sim.lcmlog").string();
  ASSERT_EQ(run(bin_dir() +
                    "/traverse-sim --config configs/sim.yaml --world configs/worlds/office.yaml "
                    "--route configs/routes/office-s2.yaml --profile ideal --seed 1 --duration 14 "
                    "--profile-every 1000000000 --out " +
                    sim,
                120)
                .exit_code,
            0);
  const std::string deploy = (dir / "deploy.yaml").string();
  std::ofstream(deploy)
      << "processes:\n"
         "  - {name: frontend, program: traverse-frontend, config: configs/frontend.yaml}\n"
         "  - {name: backend, program: traverse-backend, config: configs/backend.yaml,\n"
         "     args: [--state-dir, \"{out}/state/backend\"],\n"
         "     on_death: restart, max_restarts: 2, restart_delay_s: 0.2}\n"
         "  - {name: densifier, program: traverse-densifier, config: configs/densifier.yaml}\n";
  const auto launch = [&](const std::string& out) {
    return run("TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " + deploy +
                   " --log " + sim + " --out " + out + " --grace 2",
               180);
  };
  const auto undisturbed = launch((dir / "undisturbed").string());
  ASSERT_EQ(undisturbed.exit_code, 0) << undisturbed.output;

  int killed = 0;
  std::thread killer(
      [&] { killed = kill_into_replay(dir / "killed-run" / "processes.json", "backend", 7.0); });
  const auto killed_run = launch((dir / "killed-run").string());
  killer.join();
  ASSERT_GT(killed, 0) << killed_run.output;
  EXPECT_EQ(killed_run.exit_code, 0) << killed_run.output;
  EXPECT_NE(killed_run.output.find("backend died (killed by SIGKILL (died)); restart 1 of 2"),
            std::string::npos)
      << killed_run.output;
  const std::string backend_log = read_text(dir / "killed-run" / "backend.log");
  EXPECT_NE(backend_log.find("traverse-backend: resumed from"), std::string::npos) << backend_log;

  // The products. The run log is whole (count_channels fails the test on damage).
  count_channels((dir / "killed-run" / "run.lcmlog").string());
  const int32_t keys_a = key_pose_count((dir / "undisturbed" / "run.lcmlog").string());
  const int32_t keys_b = key_pose_count((dir / "killed-run" / "run.lcmlog").string());
  ASSERT_GT(keys_a, 30);
  // Down for about 0.5 s (restart delay, start-up, resume) plus up to 1 s since the last
  // snapshot, at three key poses a second: at most 5 fewer, allowed 8. The key poses after the
  // gap fall on other scans (their interval starts again from the resumed last key pose), so the
  // runs are compared through the ground truth.
  EXPECT_GE(keys_b + 8, keys_a);
  const double keys_rmse_a = position_rmse(dir / "undisturbed", "KEY_POSES");
  const double keys_rmse_b = position_rmse(dir / "killed-run", "KEY_POSES");
  const double dense_a = position_rmse(dir / "undisturbed", "DENSE_SEGMENTS");
  const double dense_b = position_rmse(dir / "killed-run", "DENSE_SEGMENTS");
  EXPECT_LT(std::abs(keys_rmse_a - keys_rmse_b), 0.002) << keys_rmse_a << " " << keys_rmse_b;
  EXPECT_LT(std::abs(dense_a - dense_b), 0.002) << dense_a << " " << dense_b;
  std::printf(
      "crash recovery: key poses %d / %d, key pose RMSE %.6f / %.6f m, dense RMSE "
      "%.6f / %.6f m (undisturbed / killed and resumed)\n",
      keys_a, keys_b, keys_rmse_a, keys_rmse_b, dense_a, dense_b);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
