#include "final_trajectory.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "synthetic.hpp"

namespace traverse::evaluator {
namespace {

using test::circle_pose;

StampedPose at(int64_t utime_us, double dx_m = 0.0) {
  const Pose2 p = circle_pose(1e-6 * static_cast<double>(utime_us));
  return {utime_us, Pose2(p.x() + dx_m, p.y(), p.theta())};
}

TEST(KeyPoseTrajectory, NewestPosePerIdWins) {
  KeyPoseTrajectory k;
  k.update(0, at(1'000'000));
  k.update(1, at(2'000'000, 0.5));  // first estimate, 0.5 m off
  k.update(2, at(3'000'000, 0.5));
  k.update(1, at(2'000'000));  // revised by an optimisation
  const Trajectory t = k.trajectory();
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(k.replaced(), 1u);
  EXPECT_NEAR(t[1].pose.x(), at(2'000'000).pose.x(), 1e-12);  // the revision, not the first
  EXPECT_NEAR(t[2].pose.x(), at(3'000'000, 0.5).pose.x(), 1e-12);
  EXPECT_EQ(t[0].utime, 1'000'000);
}

TEST(KeyPoseTrajectory, NonFiniteNewestPoseIsLeftOutNotReplacedByOlder) {
  KeyPoseTrajectory k;
  k.update(0, at(1'000'000));
  k.update(0, {1'000'000, Pose2(std::nan(""), 0.0, 0.0)});
  EXPECT_TRUE(k.trajectory().empty());
}

DenseSegment segment(int64_t first, int32_t revision, int64_t t0_us, double dx_m) {
  DenseSegment s{first, first + 1, revision, {}};
  for (int i = 0; i <= 10; ++i) s.poses.push_back(at(t0_us + i * 100'000, dx_m));
  return s;
}

TEST(DenseTrajectory, NewestRevisionWinsAndSharedEndsAreKeptOnce) {
  DenseTrajectory d;
  EXPECT_TRUE(d.update(segment(0, 0, 1'000'000, 0.2)));
  EXPECT_TRUE(d.update(segment(1, 0, 2'000'000, 0.2)));   // starts where segment 0 ends
  EXPECT_TRUE(d.update(segment(0, 1, 1'000'000, 0.0)));   // moved by an optimisation
  EXPECT_FALSE(d.update(segment(0, 0, 1'000'000, 0.7)));  // an old revision arriving late
  EXPECT_TRUE(d.update(segment(1, 0, 2'000'000, 0.1)));   // same revision resent: later wins
  EXPECT_EQ(d.stale(), 1u);
  const Trajectory t = d.trajectory();
  ASSERT_EQ(t.size(), 21u);  // 11 + 11 poses, one shared
  for (const StampedPose& p : t) {
    // The shared pose at 2 s comes from segment 0 (revision 1, exact); the rest of segment 1
    // is its resend, 0.1 m off.
    const double expected_dx_m = p.utime <= 2'000'000 ? 0.0 : 0.1;
    EXPECT_NEAR(p.pose.x() - at(p.utime).pose.x(), expected_dx_m, 1e-12) << p.utime;
  }
}

}  // namespace
}  // namespace traverse::evaluator
