#include "trajectory_prep.hpp"

#include <gtest/gtest.h>

#include <random>

namespace traverse::backend {
namespace {

constexpr int64_t kScanPeriodUs = 25000;  // 40 Hz

// Constant body-frame velocity (vx [m/s], omega [rad/s]) for n scans.
std::vector<StampedPose> drive(int n, double vx, double omega) {
  std::vector<StampedPose> poses{{0, Pose2()}};
  const double dt = 1e-6 * kScanPeriodUs;
  for (int k = 1; k < n; ++k) {
    poses.push_back(
        {k * kScanPeriodUs, poses.back().T_world_base * Pose2(vx * dt, 0.0, omega * dt)});
  }
  return poses;
}

// Every pose through `prep`, the one it holds back included.
std::vector<PreparedPose> prepare_all(TrajectoryPrep& prep, const std::vector<StampedPose>& poses) {
  std::vector<PreparedPose> out;
  for (const StampedPose& p : poses) {
    if (auto q = prep.add({p.utime, p.T_world_base})) out.push_back(*q);
  }
  if (auto q = prep.finish()) out.push_back(*q);
  return out;
}

TEST(JumpSmoothing, KeepsSmoothMotionUnchanged) {
  for (const auto& poses : {drive(200, 1.2, 0.0), drive(200, 0.8, 0.7), drive(200, 0.0, 0.0)}) {
    const SmoothedTrajectory s = smooth_jumps(poses, {});
    EXPECT_TRUE(s.replaced_steps.empty());
    ASSERT_EQ(s.poses.size(), poses.size());
    EXPECT_NEAR(
        (s.poses.back().T_world_base.translation() - poses.back().T_world_base.translation())
            .norm(),
        0.0, 1e-9);
  }
}

TEST(JumpSmoothing, IgnoresJitterAtRest) {
  std::mt19937 rng(1);
  std::normal_distribution<double> mm(0.0, 0.001), mrad(0.0, 0.001);
  std::vector<StampedPose> poses;
  for (int k = 0; k < 200; ++k)
    poses.push_back({k * kScanPeriodUs, Pose2(mm(rng), mm(rng), mrad(rng))});
  EXPECT_TRUE(smooth_jumps(poses, {}).replaced_steps.empty());
}

TEST(JumpSmoothing, ReplacesALoopClosureJumpAndCarriesTheRestAlong) {
  // Walking straight at 1 m/s; at scan 80 the frontend snaps 0.4 m sideways and 0.3 m back.
  std::vector<StampedPose> poses = drive(160, 1.0, 0.0);
  for (std::size_t k = 80; k < poses.size(); ++k) {
    poses[k].T_world_base = Pose2(-0.3, 0.4, 0.0) * poses[k].T_world_base;
  }
  const SmoothedTrajectory s = smooth_jumps(poses, {});
  ASSERT_EQ(s.replaced_steps, std::vector<int>{80});
  // The replaced step is the average step (0.025 m forward), so the smoothed trajectory is the
  // jump-free one.
  const std::vector<StampedPose> clean = drive(160, 1.0, 0.0);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(
        (s.poses[k].T_world_base.translation() - clean[k].T_world_base.translation()).norm(), 0.0,
        1e-9)
        << k;
    EXPECT_EQ(s.poses[k].utime, poses[k].utime);
  }
}

TEST(JumpSmoothing, ReplacesAHeadingJump) {
  std::vector<StampedPose> poses = drive(100, 0.5, 0.1);
  for (std::size_t k = 60; k < poses.size(); ++k) {
    poses[k].T_world_base = poses[k].T_world_base * Pose2(0.0, 0.0, 0.3);  // 12 rad/s in one scan
  }
  EXPECT_EQ(smooth_jumps(poses, {}).replaced_steps, std::vector<int>{60});
}

TEST(JumpSmoothing, ReplacesAnOutlierWithoutMovingWhatFollows) {
  // At 0.35 m/s one pose sits 12 mm to the side and the next is back on the path (a bad match
  // seen on the simulated office): only that pose changes.
  std::vector<StampedPose> poses = drive(100, 0.35, 0.0);
  const std::vector<StampedPose> clean = poses;
  poses[50].T_world_base = poses[50].T_world_base * Pose2(0.004, -0.012, 0.0);
  JumpSmoothingConfig config;
  config.min_jump_m = 0.005;                              // a 12 mm outlier counts
  EXPECT_TRUE(smooth_jumps(poses, {}).outliers.empty());  // by default it is left to the links
  const SmoothedTrajectory s = smooth_jumps(poses, config);
  EXPECT_TRUE(s.replaced_steps.empty());
  ASSERT_EQ(s.outliers, std::vector<int>{50});
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_NEAR(
        (s.poses[k].T_world_base.translation() - clean[k].T_world_base.translation()).norm(), 0.0,
        1e-9)
        << k;
  }
}

TEST(JumpSmoothing, DeviationsBelowTheMinimumAreNotJumps) {
  // 4 mm sideways at 0.2 m/s (5 mm per scan) turns the step by 0.67 rad: matching noise, not a
  // jump, unless the minimum and the direction limit are set tighter.
  JumpSmoothingConfig fine;
  fine.min_jump_m = 0.005;
  std::vector<StampedPose> poses = drive(100, 0.2, 0.0);
  for (std::size_t k = 50; k < poses.size(); ++k) {
    poses[k].T_world_base = Pose2(0.0, 0.004, 0.0) * poses[k].T_world_base;
  }
  const SmoothedTrajectory s = smooth_jumps(poses, fine);
  EXPECT_TRUE(s.replaced_steps.empty());
  EXPECT_TRUE(s.outliers.empty());
  JumpSmoothingConfig strict;
  strict.min_jump_m = 0.001;
  strict.max_direction_change_rad = 0.5;
  const SmoothedTrajectory t = smooth_jumps(poses, strict);
  EXPECT_EQ(t.replaced_steps, std::vector<int>{50});
  EXPECT_TRUE(t.outliers.empty());
}

TEST(KeyPoses, ThreePerSecondByTime) {
  const std::vector<StampedPose> poses = drive(121, 1.0, 0.0);  // 3 s at 40 Hz
  const std::vector<int> keys = select_key_poses(poses, {});
  // 333333 us at 25000 us per scan: every 14th scan.
  ASSERT_EQ(keys.size(), 9u);
  for (std::size_t i = 0; i < keys.size(); ++i) EXPECT_EQ(keys[i], static_cast<int>(14 * i));
}

TEST(KeyPoses, ByDistanceAndAngle) {
  KeyPoseConfig by_distance;
  by_distance.interval_us = 0;
  by_distance.distance_m = 0.5;
  const std::vector<StampedPose> straight = drive(200, 1.0, 0.0);
  const std::vector<int> keys = select_key_poses(straight, by_distance);
  ASSERT_GT(keys.size(), 5u);
  for (std::size_t i = 1; i < keys.size(); ++i) {
    const double d = (straight[keys[i]].T_world_base.translation() -
                      straight[keys[i - 1]].T_world_base.translation())
                         .norm();
    EXPECT_GE(d, 0.5 - 1e-9);
    EXPECT_LT(d, 0.5 + 0.025 + 1e-9);
  }
  KeyPoseConfig by_angle;
  by_angle.interval_us = 0;
  by_angle.angle_rad = 0.5;
  const std::vector<int> turning = select_key_poses(drive(200, 0.0, 1.0), by_angle);
  EXPECT_EQ(turning.size(), 1u + 199 / 20);  // 0.025 rad per scan: every 20 scans
  EXPECT_EQ(select_key_poses(drive(200, 0.0, 1.0), by_distance).size(), 1u);  // no travel
}

// A log whose clock failed (Kummerle's full-rate intel: 3,800 of 13,600 intervals under 5 ms,
// the rest up to seconds): a turn on the spot, 0.15 rad a scan, stamped 80 ms and 2 ms apart by
// turns. The median interval (2 ms) made it a scanner's stream, the smoothing saw 75 rad/s and
// replaced real turns (the full graph's headings 10-20 degrees off the frontend's there). Now a
// stream needs every recent interval between 5 and 100 ms; the prepared poses keep the
// frontend's steps.
TEST(TrajectoryPrep, StampsSqueezedTogetherAreNotAStream) {
  std::vector<StampedPose> poses{{0, Pose2()}};
  const int64_t intervals_us[] = {80000, 2000, 2000, 80000, 2000};
  for (int k = 0; k < 40; ++k) {
    poses.push_back({poses.back().utime + intervals_us[k % 5],
                     poses.back().T_world_base * Pose2(0.0, 0.0, 0.15)});
  }
  for (const int64_t min_stream_us : {int64_t{5000}, int64_t{0}}) {
    JumpSmoothingConfig config;
    config.sparse_interval_us = 100000;  // configs/backend.yaml
    config.min_stream_interval_us = min_stream_us;
    TrajectoryPrep prep(config);
    const std::vector<PreparedPose> out = prepare_all(prep, poses);
    ASSERT_EQ(out.size(), poses.size());
    const double error =
        std::abs(wrap_angle(out.back().T_world_base.theta() - poses.back().T_world_base.theta()));
    if (min_stream_us > 0) {
      EXPECT_EQ(prep.counters().jumps_smoothed + prep.counters().outliers_replaced, 0);
      EXPECT_LT(error, 1e-9);  // [rad]
    } else {                   // no lower bound: taken as a stream
      EXPECT_GT(prep.counters().jumps_smoothed + prep.counters().outliers_replaced, 0);
      EXPECT_GT(error, 0.1);  // [rad]
    }
  }
}

// A scanner's stream stays paced through a pause in it (intel's logger stalls up to 2 s); a log
// subsampled by travel (a scan seconds apart) and stamps squeezed together (all-zero stamps
// restamped 1 us apart) are not (frontend_chain.hpp: how the drift model weighs one ambiguous
// match).
TEST(TrajectoryPrep, AStreamStaysPacedThroughAPause) {
  const auto paced_share = [](const std::vector<int64_t>& intervals_us) {
    JumpSmoothingConfig config;
    config.sparse_interval_us = 100000;  // configs/backend.yaml
    TrajectoryPrep prep(config);
    int64_t t = 0;
    int paced = 0, n = 0;
    for (std::size_t k = 0; k < 200; ++k) {
      t += intervals_us[k % intervals_us.size()];
      const auto q = prep.add({t, Pose2(0.1 * static_cast<double>(k), 0.0, 0.0)});
      if (q && k > 60) {
        ++n;
        if (q->paced) ++paced;
      }
    }
    return static_cast<double>(paced) / n;
  };
  std::vector<int64_t> stream(40, 100000);  // 10 Hz ...
  stream.push_back(2000000);                // ... with a 2 s pause every 4 s
  EXPECT_EQ(paced_share(stream), 1.0);
  EXPECT_EQ(paced_share({80000, 1000, 1000, 300000}), 1.0);  // bursts after gaps (intel)
  EXPECT_EQ(paced_share({2000000, 3400000}), 0.0);           // subsampled by travel
  EXPECT_EQ(paced_share({1}), 0.0);                          // all-zero stamps, restamped
}

// A frontend that flips between two places a few decimetres apart, scan after scan, and back
// (the realistic office-rooms route: Hector at 75 Hz in a doorway with a 1-degree scanner, steps
// of 0.2-0.3 m in 13 ms). The flips straddle the smoothing's min_jump_m: an out-step above it is
// taken for a jump and replaced, its way back below it is kept, and each such pair leaves the
// prepared trajectory a flip's width off the frontend for good (office-rooms, 300 s: full graph
// 1.67 m position RMSE against the frontend's 0.255 m). Disabled, the steps go in as they are.
TEST(TrajectoryPrep, AFrontendFlippingBetweenTwoPlacesIsNotCarriedOffWhenSmoothingIsOff) {
  std::vector<StampedPose> poses = drive(400, 0.5, 0.0);
  // Sideways offsets of the frontend's poses: out 0.32 m and back in two steps of 0.2 and
  // 0.12 m; later out 0.2 m and back past the path by 0.11 m, then onto it.
  const auto flip = [&](int k, double y) {
    poses[k].T_world_base = Pose2(0.0, y, 0.0) * poses[k].T_world_base;
  };
  for (int k = 100; k < 103; ++k) flip(k, 0.32);
  flip(103, 0.12);
  for (int k = 200; k < 203; ++k) flip(k, -0.2);
  flip(203, 0.11);
  const auto last_offset = [&](bool enabled) {
    JumpSmoothingConfig config;
    config.enabled = enabled;
    TrajectoryPrep prep(config);
    const std::vector<PreparedPose> out = prepare_all(prep, poses);
    EXPECT_EQ(out.size(), poses.size());
    return (out.back().T_world_base.translation() - poses.back().T_world_base.translation()).norm();
  };
  EXPECT_GT(last_offset(true), 0.2);  // [m] carried off by a flip
  EXPECT_LT(last_offset(false), 1e-9);
}

}  // namespace
}  // namespace traverse::backend
