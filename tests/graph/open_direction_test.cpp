// A robot without wheel encoders (1-degree scanner at 75 Hz, IMU) leaving an office into the bare
// corridor of the office-rooms world (scripts/eval-route.sh office-rooms, realistic profile, seed
// 3, first 90 s, frontend alone). Along the corridor's axis the scans hold almost nothing; single
// matches landed centimetres off along it, the velocity of the last poses took each as metres a
// second and the next predictions carried it on: 5.5 m off within two seconds of entering the
// corridor at 84 s. docs/frontends.md, "Open directions without odometry". Measured (2026-11-29):
// with the velocity unbounded (motion_prior.max_acceleration_mps2 0) position RMSE 1.140 m, RPE
// over 10 m 1.333 m (as shipped); bounded at 2 m/s^2 0.185 and 0.195 m; with the open direction
// also held at the bounded velocity's prediction (matcher.degeneracy_hold_without_odometry)
// 0.099 and 0.073 m. Both are opt-in: docs/frontends.md says where they lose.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "graph_test_util.hpp"

namespace traverse::graph_test {
namespace {

struct Figures {
  double rmse_m = 0.0;
  double rpe_10m_m = 0.0;
};

Figures office_rooms_seed3(const std::string& tag, const std::string& sets) {
  const std::string json = eval_route(
      "office-rooms --seed 3 --duration 90 --stages frontend --offline --tag " + tag + sets);
  const Figures f{json_number(json, "position_rmse_m"), json_number(json, "rpe_10m_m")};
  std::printf(
      "office-rooms seed 3, 90 s, frontend (%s): position RMSE %.3f m, RPE over 10 m %.3f m\n",
      tag.c_str(), f.rmse_m, f.rpe_10m_m);
  return f;
}

TEST(OpenDirection, ABoundedVelocityKeepsARobotWithoutWheelsInTheCorridor) {
  const Figures f = office_rooms_seed3("open-direction-bounded",
                                       " --set frontend.motion_prior.max_acceleration_mps2=2");
  EXPECT_LT(f.rmse_m, 0.4);
  EXPECT_LT(f.rpe_10m_m, 0.4);
}

TEST(OpenDirection, HeldAtTheBoundedVelocityTheCorridorAxisHoldsCloser) {
  const Figures f = office_rooms_seed3("open-direction-held",
                                       " --set frontend.motion_prior.max_acceleration_mps2=2 --set "
                                       "frontend.matcher.degeneracy_hold_without_odometry=true");
  EXPECT_LT(f.rmse_m, 0.15);
  EXPECT_LT(f.rpe_10m_m, 0.15);
}

// The pushed cart without wheel encoders of the corridor world starts in its 60 m bare corridor
// (corridor-return, realistic profile, seed 1, first 40 s, frontend alone): from its first scans
// the axis is open, and the velocity the hold would hold to is the standstill it started from.
// Held from the start the estimate stays there while the cart walks away; held only after the
// scans determined the whole pose for 0.5 s without a break, and for at most 3 s after the last
// that did, the axis is left to the match here, as it is with no hold. Measured (2026-11-29):
// held from the start position RMSE 10.07 m, RPE over 10 m 9.70 m; with the two limits 0.088 and
// 0.109 m (no hold at all, as shipped: 0.177 and 0.219 m).
TEST(OpenDirection, TheHoldWaitsForAVelocityTheScansMeasured) {
  const std::string hold =
      " --set frontend.motion_prior.max_acceleration_mps2=2 --set "
      "frontend.matcher.degeneracy_hold_without_odometry=true";
  const auto run = [](const std::string& tag, const std::string& sets) {
    const std::string json = eval_route(
        "corridor-return --seed 1 --duration 40 --stages frontend --offline --tag " + tag + sets);
    const Figures f{json_number(json, "position_rmse_m"), json_number(json, "rpe_10m_m")};
    std::printf(
        "corridor-return seed 1, 40 s, frontend (%s): position RMSE %.3f m, RPE over 10 m "
        "%.3f m\n",
        tag.c_str(), f.rmse_m, f.rpe_10m_m);
    return f;
  };
  const Figures gated =
      run("open-direction-gated", hold +
                                      " --set frontend.matcher.degeneracy_hold_after_s=0.5 --set "
                                      "frontend.matcher.degeneracy_hold_max_s=3");
  EXPECT_LT(gated.rmse_m, 0.3);
  EXPECT_LT(gated.rpe_10m_m, 0.3);
  // The control: the same hold without the limits is lost here (what the limits are for).
  const Figures held = run("open-direction-held-from-start", hold);
  EXPECT_GT(held.rmse_m, 1.0);
}

}  // namespace
}  // namespace traverse::graph_test
