// Crash recovery of the mapper and the frontend (docs/deployment.md): the whole graph with the
// deployment's state directories runs 14 s of office-s2 (ideal profile) live three times:
// undisturbed, with the mapper SIGKILLed 7 s into the replay, and with the frontend SIGKILLed 7 s
// in. The launcher restarts the killed process, it resumes from its state, and the final products
// are compared with the undisturbed run's (tolerances and their reasons at each check).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <thread>

#include "graph_test_util.hpp"
#include "lcm_log.hpp"
#include "se2.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::graph_test {
namespace {

// Across the largest time gap between two consecutive frontend poses (a restarted frontend's
// time down): the gap [s], and the error [m] of the frontend's motion over it against the truth's
// (a restarted frontend that jumps shows here).
std::pair<double, double> step_across_gap(const std::vector<pose2d_t>& est,
                                          const std::vector<pose2d_t>& truth) {
  const auto truth_at = [&](int64_t t) {
    auto it = std::lower_bound(truth.begin(), truth.end(), t,
                               [](const pose2d_t& p, int64_t u) { return p.utime < u; });
    if (it == truth.end()) --it;
    return Pose2(it->x, it->y, it->theta);
  };
  std::size_t at = 0;
  int64_t widest = 0;  // [us]
  for (std::size_t i = 1; i < est.size(); ++i) {
    if (est[i].utime - est[i - 1].utime > widest) {
      widest = est[i].utime - est[i - 1].utime;
      at = i;
    }
  }
  if (at == 0) return {0.0, 0.0};
  const pose2d_t &a = est[at - 1], &b = est[at];
  const Pose2 step = Pose2(a.x, a.y, a.theta).inverse() * Pose2(b.x, b.y, b.theta);
  const Pose2 true_step = truth_at(a.utime).inverse() * truth_at(b.utime);
  return {static_cast<double>(b.utime - a.utime) * 1e-6,
          (step.translation() - true_step.translation()).norm()};
}

// The graph of the deployment files (configs/deploy/pipeline.yaml: state directories, restart
// policies) on 14 s of office-s2 with every fifth profile.
struct Runs {
  std::filesystem::path dir;
  std::string sim, deploy;

  // One live run into `out`. A verdict that failed (exit 3: messages lost, out of order) says the
  // machine dropped datagrams (a 2-core machine under a load of 15 does; the processes' own
  // counts say so), not that recovery failed: such a run is made once more, and the one compared
  // must be clean.
  CommandResult launch(const std::string& out, const std::function<void()>& during = {}) const {
    CommandResult r;
    for (int attempt = 0; attempt < 2 && r.exit_code != 0; ++attempt) {
      if (attempt > 0) {
        std::printf("recovery: %s: verdict failed (exit 3), run again:\n%s\n", out.c_str(),
                    r.output.substr(r.output.size() > 2000 ? r.output.size() - 2000 : 0).c_str());
        std::filesystem::remove_all(dir / out);
      }
      std::thread side;
      if (during) side = std::thread(during);
      r = run("TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " + deploy +
                  " --log " + sim + " --out " + (dir / out).string() + " --grace 2",
              180);
      if (side.joinable()) side.join();
      if (r.exit_code != 3) break;
    }
    return r;
  }
  // Runs the graph into `out` and SIGKILLs `victim` 7 s into the replay; its pid (0: not killed).
  int launch_and_kill(const std::string& out, const std::string& victim,
                      CommandResult* result) const {
    int pid = 0;
    *result =
        launch(out, [&] { pid = kill_into_replay(dir / out / "processes.json", victim, 7.0); });
    return pid;
  }
};

// One test for both, so that they share the simulation and the undisturbed run.
TEST(ProcessRecovery, MapperAndFrontendKilledMidRunResumeFromTheirState) {
  Runs runs{temp_dir("recovery"), "", ""};
  runs.sim = (runs.dir / "sim.lcmlog").string();
  ASSERT_EQ(run(bin_dir() +
                    "/traverse-sim --config configs/sim.yaml --world configs/worlds/office.yaml "
                    "--route configs/routes/office-s2.yaml --profile ideal --seed 1 --duration 14 "
                    "--profile-every 5 --out " +
                    runs.sim,
                120)
                .exit_code,
            0);
  runs.deploy = (runs.dir / "deploy.yaml").string();
  std::ofstream(runs.deploy)
      << "processes:\n"
         "  - {name: frontend, program: traverse-frontend, config: configs/frontend.yaml,\n"
         "     args: [--state-dir, \"{out}/state/frontend\"],\n"
         "     on_death: restart, max_restarts: 2, restart_delay_s: 0.2}\n"
         "  - {name: backend, program: traverse-backend, config: configs/backend.yaml,\n"
         "     args: [--state-dir, \"{out}/state/backend\"]}\n"
         "  - {name: densifier, program: traverse-densifier, config: configs/densifier.yaml}\n"
         "  - {name: mapper, program: traverse-mapper, config: configs/mapper.yaml,\n"
         "     args: [--out, \"{out}/mapper\", --state-dir, \"{out}/state/mapper\"],\n"
         "     on_death: restart, max_restarts: 2, restart_delay_s: 0.2}\n";
  const auto undisturbed = runs.launch("undisturbed");
  ASSERT_EQ(undisturbed.exit_code, 0) << undisturbed.output;
  const std::filesystem::path& dir = runs.dir;

  // The mapper.
  {
    CommandResult r;
    ASSERT_GT(runs.launch_and_kill("mapper-killed", "mapper", &r), 0) << r.output;
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("mapper died (killed by SIGKILL (died)); restart 1 of 2"),
              std::string::npos)
        << r.output;
    const std::string log = read_text(dir / "mapper-killed" / "mapper.log");
    EXPECT_NE(log.find("traverse-mapper: resumed from"), std::string::npos) << log;
    count_channels((dir / "mapper-killed" / "run.lcmlog").string());  // the run log is whole

    const int64_t points_a = cloud_points(dir / "undisturbed" / "mapper" / "cloud.ply");
    const int64_t points_b = cloud_points(dir / "mapper-killed" / "mapper" / "cloud.ply");
    const auto voxels_a = occupied_voxels(dir / "undisturbed" / "mapper" / "map.bt");
    const auto voxels_b = occupied_voxels(dir / "mapper-killed" / "mapper" / "map.bt");
    ASSERT_GT(points_a, 100000);
    ASSERT_GT(voxels_a.size(), 10000u);
    std::size_t common = 0;
    for (const auto& k : voxels_b) common += voxels_a.count(k);
    const double missing = 1.0 - static_cast<double>(common) / voxels_a.size();
    const double extra =
        1.0 - static_cast<double>(common) / std::max<std::size_t>(1, voxels_b.size());
    std::printf(
        "mapper recovery: cloud points %lld / %lld, occupied voxels %zu / %zu, of the undisturbed "
        "run's voxels %.2f %% missing, %.2f %% of the resumed run's not in it (undisturbed / "
        "killed and resumed)\n",
        static_cast<long long>(points_a), static_cast<long long>(points_b), voxels_a.size(),
        voxels_b.size(), 100.0 * missing, 100.0 * extra);
    // What is lost: the profiles of the time the mapper was down (restart delay 0.2 s and
    // start-up) and those whose trajectory segments came meanwhile (the densifier trails the
    // profiles by about a key pose interval): about a second of the 14 s run, under 10 % of the
    // points (4.9 % measured); allowed 15 %. Nothing from before the kill is lost (without the
    // state the restarted mapper would start empty). Two live runs differ by a few profiles at
    // the end (which segments came before the graph stopped): up to 3 % more allowed. The
    // voxels lose about as much as the points (5.7 % measured): allowed 10 %. Voxels the
    // undisturbed run has not would come from the two runs' trajectories (each live backend
    // picks its key scans on its own timing, millimetres apart, so a few voxels on either side
    // of a boundary; none measured): allowed 5 %.
    EXPECT_GE(points_b, points_a * 85 / 100);
    EXPECT_LE(points_b, points_a + points_a * 3 / 100);
    EXPECT_LT(missing, 0.10);
    EXPECT_LT(extra, 0.05);
  }

  // The frontend.
  {
    CommandResult r;
    ASSERT_GT(runs.launch_and_kill("frontend-killed", "frontend", &r), 0) << r.output;
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("frontend died (killed by SIGKILL (died)); restart 1 of 2"),
              std::string::npos)
        << r.output;
    const std::string log = read_text(dir / "frontend-killed" / "frontend.log");
    EXPECT_NE(log.find("traverse-frontend: resumed from"), std::string::npos) << log;
    const std::string run_log = (dir / "frontend-killed" / "run.lcmlog").string();
    count_channels(run_log);

    const double keys_a = position_rmse(dir / "undisturbed", "KEY_POSES");
    const double keys_b = position_rmse(dir / "frontend-killed", "KEY_POSES");
    const double dense_a = position_rmse(dir / "undisturbed", "DENSE_SEGMENTS");
    const double dense_b = position_rmse(dir / "frontend-killed", "DENSE_SEGMENTS");
    const auto [gap_s, step_error_m] =
        step_across_gap(poses_on(run_log, "POSE_FRONTEND"), poses_on(run_log, "POSE_GROUND_TRUTH"));
    std::printf(
        "frontend recovery: key pose RMSE %.6f / %.6f m, dense RMSE %.6f / %.6f m (undisturbed / "
        "killed and resumed); no frontend pose for %.3f s, its motion over that gap off the "
        "truth's "
        "by %.6f m\n",
        keys_a, keys_b, dense_a, dense_b, gap_s, step_error_m);
    // The restarted frontend re-tracks its saved window (at most save_period_s old) and takes the
    // next scan from its last pose: the backend sees no jump. Down for the restart delay and its
    // start-up (0.2 s and more), the platform moves decimetres meanwhile; a frontend that lost
    // track would be off by about that much. The frontend's own step errors reach about 1.5 cm on
    // this route (an undisturbed run's worst between two scans); allowed 2 cm.
    EXPECT_GT(gap_s, 0.2);
    EXPECT_LT(step_error_m, 0.02);
    // The key poses and the dense trajectory through the gap: within 2 mm of the undisturbed run's
    // RMSE (as for the backend's recovery, crash_recovery_test.cpp).
    EXPECT_LT(std::abs(keys_a - keys_b), 0.002) << keys_a << " " << keys_b;
    EXPECT_LT(std::abs(dense_a - dense_b), 0.002) << dense_a << " " << dense_b;
  }
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
