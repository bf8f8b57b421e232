#include "hector/deskew.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "hector/yaw_integrator.hpp"
#include "synthetic_scans.hpp"

namespace traverse::frontend {
namespace {

TEST(YawIntegrator, IntegratesLinearRateExactly) {
  YawIntegrator yaw;
  // Rate 0.1 + 2 t [rad/s] sampled every 5 ms: the trapezoid rule is exact for it.
  for (int64_t t = 0; t <= 1'000'000; t += 5000) {
    yaw.add(t, Eigen::Vector3d(0, 0, 0.1 + 2.0 * 1e-6 * t));
  }
  auto angle = [](double s) { return 0.1 * s + s * s; };
  EXPECT_NEAR(yaw.heading_change(0, 1'000'000), angle(1.0), 1e-12);
  EXPECT_NEAR(yaw.heading_change(123'456, 654'321), angle(0.654321) - angle(0.123456), 1e-9);
  EXPECT_NEAR(yaw.heading_change(654'321, 123'456), angle(0.123456) - angle(0.654321), 1e-9);
  EXPECT_TRUE(yaw.covers(0, 1'000'000));
  EXPECT_FALSE(yaw.covers(0, 1'000'001));
  EXPECT_FALSE(yaw.add(1'000'000, Eigen::Vector3d::Zero()));  // not after the last sample
}

TEST(YawIntegrator, RotatesImuRateIntoBase) {
  // IMU mounted upside down (rolled by pi): its z rate is minus the base's.
  const Eigen::Matrix3d R_base_imu = Eigen::Vector3d(1, -1, -1).asDiagonal();
  YawIntegrator yaw(R_base_imu);
  yaw.add(0, Eigen::Vector3d(0, 0, -0.5));
  yaw.add(1'000'000, Eigen::Vector3d(0, 0, -0.5));
  EXPECT_NEAR(yaw.heading_change(0, 1'000'000), 0.5, 1e-12);
}

// Largest distance of the points from their best-fitting line [m].
double line_residual(const std::vector<Eigen::Vector2d>& pts) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p / static_cast<double>(pts.size());
  Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
  for (const auto& p : pts) C += (p - mean) * (p - mean).transpose();
  const Eigen::Vector2d normal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(C).eigenvectors().col(0);
  double worst = 0.0;
  for (const auto& p : pts) worst = std::max(worst, std::abs(normal.dot(p - mean)));
  return worst;
}

// A platform turning fast while the scanner sweeps a straight wall: the raw points bend, the
// de-skewed ones lie on a line again.
TEST(Deskew, RecoversStraightWallFromRotatingSweep) {
  const synthetic::World wall = {{{3.0, -30.0}, {3.0, 30.0}}};
  const double omega = 1.5;  // [rad/s] turning on the spot
  auto truth = [&](int64_t t) { return Pose2(0.0, 0.0, omega * 1e-6 * static_cast<double>(t)); };
  synthetic::SweepSpec spec;
  spec.n_ranges = 2000;
  spec.angle_first = -1.2;
  spec.angle_step = 2.4 / 1999;
  spec.duration_us = 100'000;  // a slow sweep: 0.15 rad of turn while it lasts
  const Scan scan = synthetic::make_sweep(wall, truth, Pose2(), spec);

  YawIntegrator yaw;
  for (int64_t t = -10'000; t <= 120'000; t += 5000) yaw.add(t, Eigen::Vector3d(0, 0, omega));
  std::vector<Eigen::Vector2d> points;
  std::vector<int64_t> utimes;
  for (int i = 0; i < spec.n_ranges; ++i) {
    if (!std::isfinite(scan.ranges[i])) continue;
    const double a = scan.angle_first + i * scan.angle_step;
    points.emplace_back(scan.ranges[i] * std::cos(a), scan.ranges[i] * std::sin(a));
    utimes.push_back(scan.utime_first +
                     std::llround(spec.duration_us * (i / (spec.n_ranges - 1.0))));
  }
  ASSERT_GT(points.size(), 1500u);
  const double raw = line_residual(points);
  deskew_points(
      points, utimes, scan.utime_last,
      [&](int64_t t) { return yaw.heading_change(scan.utime_last, t); }, Eigen::Vector2d::Zero(),
      true);
  const double corrected = line_residual(points);
  EXPECT_GT(raw, 0.1);         // bent by tens of centimetres
  EXPECT_LT(corrected, 1e-6);  // straight again
  // And where the wall is in the base frame at the last point: x = 3 / cos(heading).
  const Pose2 T_end = truth(scan.utime_last);
  for (const auto& p : points) EXPECT_NEAR((T_end * p).x(), 3.0, 1e-6);
}

// Translation during the sweep: driving towards a wall at 1 m/s; de-skew with the velocity puts
// every point back on the wall seen from the end pose.
TEST(Deskew, TranslationFromConstantVelocity) {
  const synthetic::World wall = {{{3.0, -30.0}, {3.0, 30.0}}};
  auto truth = [](int64_t t) { return Pose2(1e-6 * static_cast<double>(t), 0.0, 0.0); };
  synthetic::SweepSpec spec;
  spec.n_ranges = 500;
  spec.angle_first = -1.0;
  spec.angle_step = 2.0 / 499;
  spec.duration_us = 100'000;
  const Scan scan = synthetic::make_sweep(wall, truth, Pose2(), spec);
  std::vector<Eigen::Vector2d> points;
  std::vector<int64_t> utimes;
  for (int i = 0; i < spec.n_ranges; ++i) {
    const double a = scan.angle_first + i * scan.angle_step;
    points.emplace_back(scan.ranges[i] * std::cos(a), scan.ranges[i] * std::sin(a));
    utimes.push_back(scan.utime_first +
                     std::llround(spec.duration_us * (i / (spec.n_ranges - 1.0))));
  }
  deskew_points(
      points, utimes, scan.utime_last, [](int64_t) { return 0.0; }, Eigen::Vector2d(1.0, 0.0),
      true);
  for (const auto& p : points) EXPECT_NEAR(p.x(), 3.0 - 0.1, 1e-6);  // float ranges
}

}  // namespace
}  // namespace traverse::frontend
