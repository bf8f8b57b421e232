// Sessions (docs/deployment.md): a mapping session stopped after 10 s and resumed later
// (run-graph.sh --resume) on the next 6 s goes on in the same map frame, the backend with the
// same graph, the mapper with the same cloud and OctoMap; resumed at another site, the frontend
// stops with a clear error (exit 4) instead of mapping into the old map at a wrong place.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <set>
#include <tuple>

#include "graph_test_util.hpp"
#include "lcm_log.hpp"
#include "se2.hpp"
#include "traverse/key_poses_t.hpp"
#include "traverse/pose2d_t.hpp"

namespace traverse::graph_test {
namespace {

// Copies the events of `in` with timestamps in [from_us, to_us) to `out`.
void cut(const std::string& in, const std::string& out, int64_t from_us, int64_t to_us) {
  lcm::LogFile reader(in, "r"), writer(out, "w");
  ASSERT_TRUE(reader.good() && writer.good());
  int64_t first = -1;
  while (const lcm::LogEvent* ev = reader.readNextEvent()) {
    if (first < 0) first = ev->timestamp;
    if (ev->timestamp - first < from_us || ev->timestamp - first >= to_us) continue;
    lcm::LogEvent copy = *ev;
    writer.writeEvent(&copy);
  }
}

// The largest position error [m] of `est` against the truth turned into the frame in which the
// truth pose at `utime0` is `T0`.
double worst_error(const std::vector<pose2d_t>& est, const std::vector<pose2d_t>& truth,
                   int64_t utime0, const Pose2& T0) {
  const auto truth_at = [&](int64_t t) {
    const pose2d_t* best = &truth.front();
    for (const pose2d_t& p : truth) {
      if (std::llabs(p.utime - t) < std::llabs(best->utime - t)) best = &p;
    }
    return Pose2(best->x, best->y, best->theta);
  };
  const Pose2 T_map_world = T0 * truth_at(utime0).inverse();
  double worst = 0.0;
  for (const pose2d_t& p : est) {
    const Pose2 T = T_map_world * truth_at(p.utime);
    worst = std::max(worst, std::hypot(T.x() - p.x, T.y() - p.y));
  }
  return worst;
}

TEST(Session, StoppedAndResumedLaterGoesOnInTheSameMap) {
  const auto dir = temp_dir("session");
  const std::string sim = (dir / "sim.lcmlog").string();
  ASSERT_EQ(run(bin_dir() +
                    "/traverse-sim --config configs/sim.yaml --world configs/worlds/office.yaml "
                    "--route configs/routes/office-s2.yaml --profile ideal --seed 1 --duration 16 "
                    "--profile-every 5 --out " +
                    sim,
                120)
                .exit_code,
            0);
  const std::string part1 = (dir / "part1.lcmlog").string(),
                    part2 = (dir / "part2.lcmlog").string(), far = (dir / "far.lcmlog").string();
  cut(sim, part1, 0, 10'000'000);
  cut(sim, part2, 10'000'000, 16'000'000);
  // Another site: the court, 11 to 14 s into its route (so later than session 1's end).
  const std::string court = (dir / "court.lcmlog").string();
  ASSERT_EQ(run(bin_dir() +
                    "/traverse-sim --config configs/sim.yaml --world configs/worlds/court.yaml "
                    "--route configs/routes/court-loop.yaml --profile ideal --seed 1 --duration 14 "
                    "--profile-every 1000000000 --out " +
                    court,
                120)
                .exit_code,
            0);
  cut(court, far, 11'000'000, 14'000'000);
  const std::string deploy = (dir / "deploy.yaml").string();
  std::ofstream(deploy)
      << "processes:\n"
         "  - {name: frontend, program: traverse-frontend, config: "
         "configs/frontend.yaml, args: [--state-dir, \"{out}/state/frontend\"]}\n"
         "  - {name: backend, program: traverse-backend, config: "
         "configs/backend.yaml, args: [--state-dir, \"{out}/state/backend\"]}\n"
         "  - {name: densifier, program: traverse-densifier, config: "
         "configs/densifier.yaml}\n"
         "  - {name: mapper, program: traverse-mapper, config: configs/mapper.yaml, "
         "args: [--out, \"{out}/mapper\", --state-dir, \"{out}/state/mapper\"]}\n";
  const auto session = [&](const std::string& log, const std::string& out,
                           const std::string& resume) {
    return run("TRAVERSE_BIN_DIR=" + bin_dir() + " scripts/run-graph.sh --deploy " + deploy +
                   " --offline --log " + log + " --out " + (dir / out).string() +
                   (resume.empty() ? "" : " --resume " + (dir / resume).string()),
               180);
  };
  const auto s1 = session(part1, "s1", "");
  ASSERT_EQ(s1.exit_code, 0) << s1.output;
  EXPECT_TRUE(std::filesystem::exists(dir / "s1/state/frontend/frontend.state"));
  EXPECT_TRUE(std::filesystem::exists(dir / "s1/state/backend/graph.state"));
  const auto s2 = session(part2, "s2", "s1");
  ASSERT_EQ(s2.exit_code, 0) << s2.output;
  EXPECT_NE(read_text(dir / "s2/frontend.log").find("resumed from"), std::string::npos);
  EXPECT_NE(read_text(dir / "s2/backend.log").find("resumed from"), std::string::npos);

  // Session 2's poses lie in session 1's map frame (the base at session 1's first scan).
  const std::string log1 = (dir / "s1/run.lcmlog").string(),
                    log2 = (dir / "s2/run.lcmlog").string();
  const auto f1 = poses_on(log1, "POSE_FRONTEND"), f2 = poses_on(log2, "POSE_FRONTEND");
  ASSERT_FALSE(f1.empty());
  ASSERT_FALSE(f2.empty());
  const auto truth1 = poses_on(log1, "POSE_GROUND_TRUTH"),
             truth2 = poses_on(log2, "POSE_GROUND_TRUTH");
  const Pose2 T0(f1.front().x, f1.front().y, f1.front().theta);
  const double e1 = worst_error(f1, truth1, f1.front().utime, T0);
  // Truth of session 2 carries on the simulator's world frame: tie it through session 1.
  std::vector<pose2d_t> truth = truth1;
  truth.insert(truth.end(), truth2.begin(), truth2.end());
  const double e2 = worst_error(f2, truth, f1.front().utime, T0);
  EXPECT_LT(e1, 0.03);
  EXPECT_LT(e2, 0.03);
  std::printf("session: frontend worst error session 1 %.4f m, resumed session 2 %.4f m\n", e1, e2);
  // The backend's graph goes on: session 2's key poses count on from session 1's.
  int32_t total1 = 0, total2 = 0;
  for (const auto& [log, total] : {std::pair{log1, &total1}, std::pair{log2, &total2}}) {
    LogReader reader(log);
    while (auto ev = reader.next()) {
      key_poses_t k;
      if (ev->channel == "KEY_POSES" &&
          k.decode(ev->data.data(), 0, static_cast<int>(ev->data.size())) > 0)
        *total = k.total_key_poses;
    }
  }
  EXPECT_GT(total1, 20);
  EXPECT_GT(total2, total1 + 10);

  // The mapper goes on with session 1's cloud and OctoMap: session 2's exports hold session 1's
  // points and voxels (all of them: session 2 moves none of session 1's trajectory here) and its
  // own.
  EXPECT_NE(read_text(dir / "s2/mapper.log").find("resumed from"), std::string::npos);
  const int64_t points1 = cloud_points(dir / "s1/mapper/cloud.ply"),
                points2 = cloud_points(dir / "s2/mapper/cloud.ply");
  const auto voxels1 = occupied_voxels(dir / "s1/mapper/map.bt"),
             voxels2 = occupied_voxels(dir / "s2/mapper/map.bt");
  std::size_t kept = 0;
  for (const auto& k : voxels1) kept += voxels2.count(k);
  std::printf(
      "session: cloud points %lld after session 1, %lld after session 2; %zu of session "
      "1's %zu occupied voxels in session 2's %zu\n",
      static_cast<long long>(points1), static_cast<long long>(points2), kept, voxels1.size(),
      voxels2.size());
  EXPECT_GT(points1, 50000);
  EXPECT_GT(points2, points1 + points1 / 4);  // 6 s more of profiles after 10 s
  EXPECT_EQ(kept, voxels1.size());
  EXPECT_GT(voxels2.size(), voxels1.size());

  // Resumed at another site: refused, said, nothing published.
  const auto s3 = session(far, "s3", "s1");
  EXPECT_NE(s3.exit_code, 0) << s3.output;
  const std::string log3 = read_text(dir / "s3/frontend.log");
  EXPECT_NE(log3.find("does not fit the saved map"), std::string::npos) << log3;
  // A resumed session never writes into the earlier one's folder.
  EXPECT_EQ(session(part2, "s1", "s1").exit_code, 2);
  if (!HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace traverse::graph_test
