#include "degeneracy.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "frontend.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

// The information of a corridor along a direction at `angle` in the map frame: nothing along its
// axis, 1 mm across it, 0.1 mrad in heading.
Eigen::Matrix3d corridor_information(double angle) {
  const Eigen::Matrix3d in_axes = Eigen::Vector3d(0.0, 1e6, 1e8).asDiagonal();
  return rotate_covariance(in_axes, Pose2(0.0, 0.0, angle).rotation());
}

// The axis of a corridor is found degenerate whatever its direction, and only it: the pose keeps
// the prediction along it and the match across it and in heading.
TEST(Degeneracy, HoldsOnlyTheCorridorsAxis) {
  for (const double angle : {0.0, 0.5, 2.0}) {
    const Degeneracy d = analyse_degeneracy(corridor_information(angle), 5.0, 0.01);
    ASSERT_EQ(d.directions, 1) << angle;
    EXPECT_LT(d.ratio, 1e-6);
    const Eigen::Vector2d axis(std::cos(angle), std::sin(angle)), across(-axis.y(), axis.x());
    const Pose2 predicted(1.0, 2.0, 0.3);
    // The match moved 0.4 m along the axis, 0.01 m across it and 0.002 rad.
    const Eigen::Vector2d moved = predicted.translation() + 0.4 * axis + 0.01 * across;
    const Pose2 matched(moved.x(), moved.y(), 0.302);
    const Pose2 held = remap(d, predicted, matched);
    const Eigen::Vector2d shift = held.translation() - predicted.translation();
    EXPECT_NEAR(shift.dot(axis), 0.0, 1e-9) << angle;
    EXPECT_NEAR(shift.dot(across), 0.01, 1e-9) << angle;
    EXPECT_NEAR(held.theta(), 0.302, 1e-9) << angle;
  }
}

// A room's information (every direction within a factor of a few) holds nothing; nor does a
// corridor whose axis an end wall fixes to a tenth of its width.
TEST(Degeneracy, WellDeterminedPosesAreLeftAlone) {
  const Eigen::Matrix3d room = Eigen::Vector3d(4e5, 1e6, 3e7).asDiagonal();
  EXPECT_EQ(analyse_degeneracy(room, 5.0, 0.01).directions, 0);
  const Eigen::Matrix3d end_wall = Eigen::Vector3d(4e4, 1e6, 1e8).asDiagonal();
  const Degeneracy d = analyse_degeneracy(end_wall, 5.0, 0.01);
  EXPECT_EQ(d.directions, 0);
  const Pose2 predicted(1.0, 2.0, 0.3), matched(1.3, 2.1, 0.31);
  EXPECT_NEAR((remap(d, predicted, matched).vector() - matched.vector()).norm(), 0.0, 1e-12);
}

// Heading is weighed against position by the arc it moves the points through: heading fixed to
// 0.5 mrad (4e6 / rad^2) against position to 1 mm (1e6 / m^2) is as good for points 1 m away (an
// arc of 0.5 mm), but degenerate for points 20 m away (an arc of 1 cm: 1e4 / m^2).
TEST(Degeneracy, HeadingIsWeighedByTheRangeOfThePoints) {
  const Eigen::Matrix3d information = Eigen::Vector3d(1e6, 1e6, 4e6).asDiagonal();
  EXPECT_EQ(analyse_degeneracy(information, 1.0, 0.05).directions, 0);
  const Degeneracy far = analyse_degeneracy(information, 20.0, 0.05);
  ASSERT_EQ(far.directions, 1);
  EXPECT_NEAR(std::abs(far.directions_scaled(2, 0)), 1.0, 1e-9);  // the heading
}

// The covariance: the prediction's variance along the held axis (not the match's), the match's
// across it; in metres, turned with the corridor.
TEST(Degeneracy, CovarianceTakesThePredictionsVarianceAlongTheAxis) {
  const double angle = 0.7;
  const Eigen::Matrix3d information = corridor_information(angle);
  const Degeneracy d = analyse_degeneracy(information, 5.0, 0.01);
  const Eigen::Matrix3d predicted = Eigen::Vector3d(0.04, 0.09, 1e-4).asDiagonal();
  const Eigen::Matrix3d C = remapped_covariance(d, predicted);
  const Eigen::Vector2d axis(std::cos(angle), std::sin(angle)), across(-axis.y(), axis.x());
  const Eigen::Matrix2d Cxy = C.topLeftCorner<2, 2>();
  const double along_predicted = axis.dot(predicted.topLeftCorner<2, 2>() * axis);
  EXPECT_NEAR(axis.dot(Cxy * axis), along_predicted, 1e-9);
  EXPECT_NEAR(across.dot(Cxy * across), 1e-6, 1e-9);
  EXPECT_NEAR(C(2, 2), 1e-8, 1e-12);
}

// A cart down a bare corridor (400 m, 2.2 m wide) along the map's x axis, where along_m(t) [m]
// has taken it: the frontend (degeneracy at min_ratio) and its inputs, a still IMU at 200 Hz and
// exact wheel odometry at 50 Hz, fed up to each scan.
struct CorridorCart {
  explicit CorridorCart(double min_ratio) {
    FrontendConfig config;
    config.matcher.degeneracy_min_ratio = min_ratio;
    config.calibration.extrinsic_yaw = false;
    frontend = make_frontend(config);
  }
  template <class Along>
  FrontendResult process(const Along& along_m, int64_t utime_first) {
    auto truth = [&](int64_t t) { return Pose2(-100.0 + along_m(t), 0.1, 0.0); };
    const Scan scan =
        synthetic::make_sweep(world, truth, Pose2(), testing::small_sweep(utime_first), &rng);
    for (; imu_t <= scan.utime_last; imu_t += 5000)
      frontend->add_imu(imu_t, Eigen::Vector3d::Zero());
    for (; odometry_t <= scan.utime_last + 20000; odometry_t += 20000) {
      OdometrySample o;
      o.utime = odometry_t;
      o.T_odom_base = Pose2(along_m(odometry_t), 0.0, 0.0);
      frontend->add_odometry(o);
    }
    return frontend->process(scan);
  }
  synthetic::World world = synthetic::corridor(400.0, 2.2);
  std::unique_ptr<Frontend> frontend;
  std::mt19937 rng{5};
  int64_t odometry_t = 0, imu_t = 0;
};

// A cart at 0.5 m/s down a bare corridor (no end in sight), with exact wheel odometry: the
// matcher's pull along the axis (the map's wall cells ending where it has seen them so far) is
// held off by the odometry, and the covariance along the axis grows with the odometry's instead
// of claiming what the map's history suggests.
struct CorridorRun {
  double along_error_m = 0.0;   // final, along the axis
  double across_error_m = 0.0;  // final
  double sigma_along_m = 0.0;   // final, published
  double degenerate_share = 0.0;
};
CorridorRun run_corridor(double min_ratio) {
  auto along = [](int64_t t) { return 0.5 * 1e-6 * static_cast<double>(t); };  // 0.5 m/s
  CorridorCart cart(min_ratio);
  CorridorRun run;
  int degenerate = 0, scans = 400;
  double along_first_m = 0.0;  // the map frame: the first scan's pose (the axis along x in both)
  for (int k = 0; k < scans; ++k) {
    const FrontendResult r = cart.process(along, k * testing::kPeriodUs);
    degenerate += r.diagnostics && r.diagnostics->degenerate_directions > 0;
    if (k == 0) along_first_m = along(r.utime);
    run.along_error_m = r.T_map_base.x() - (along(r.utime) - along_first_m);
    run.across_error_m = r.T_map_base.y();
    run.sigma_along_m = std::sqrt(r.covariance(0, 0));
  }
  run.degenerate_share = static_cast<double>(degenerate) / scans;
  return run;
}

TEST(Degeneracy, OdometryHoldsABareCorridorsAxis) {
  const CorridorRun held = run_corridor(0.01);
  EXPECT_GT(held.degenerate_share, 0.9);
  EXPECT_LT(std::abs(held.along_error_m), 0.01);
  EXPECT_LT(std::abs(held.across_error_m), 0.01);
  EXPECT_GT(held.sigma_along_m, 0.1);
  const CorridorRun free = run_corridor(0.0);
  EXPECT_LT(free.sigma_along_m, 0.1);  // the match claims to know the axis
}

// A cart standing in a bare corridor, then 0.4 m on along the axis while the scanner pauses for
// 0.4 s (a stream, not a sparse scan), then standing again; exact wheel odometry. Without
// odometry the last poses predict standing still, and matched from there the scan fits the map
// made at the last pose better (its far points land inside the walls seen so far), so the odometry
// check would take that match if it counted the axis, which the scan does not determine: the pose
// then stays 0.4 m behind, and the map is laid down there (aces: 2.3 m back in 1.3 s).
struct StepRun {
  double along_error_m = 0.0;  // final, along the axis
  double overruled = 0.0;      // odometry_overruled
};
StepRun run_corridor_step(double min_ratio) {
  const double step_m = 0.4;
  const int64_t gap_start_us = 1'000'000, gap_end_us = 1'400'000;
  auto along = [&](int64_t t) {
    const double s = std::clamp(static_cast<double>(t - gap_start_us) /
                                    static_cast<double>(gap_end_us - gap_start_us),
                                0.0, 1.0);
    return step_m * s;
  };
  CorridorCart cart(min_ratio);
  StepRun run;
  for (int64_t t0 = 0; t0 < 2'000'000; t0 += testing::kPeriodUs) {
    if (t0 > gap_start_us && t0 < gap_end_us) continue;  // the scanner pauses
    const FrontendResult r = cart.process(along, t0);
    run.along_error_m = r.T_map_base.x() - along(r.utime);  // the first scan stood at 0
  }
  run.overruled = testing::counters_of(*cart.frontend).at("odometry_overruled");
  return run;
}

TEST(Degeneracy, TheOdometryCheckDoesNotOverruleOdometryAlongAnAxisTheScanLeavesOpen) {
  const StepRun held = run_corridor_step(0.03);
  EXPECT_EQ(held.overruled, 0.0);
  EXPECT_LT(std::abs(held.along_error_m), 0.05);
}

}  // namespace
}  // namespace traverse::frontend
