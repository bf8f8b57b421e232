#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <map>

#include "backend.hpp"
#include "synthetic.hpp"

namespace traverse::backend {
namespace {

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

// Runs a drifting frontend through the backend; returns the RMS position error of the key poses
// of the input and of the backend [m].
std::pair<double, double> run_drive(const test::Drive& d, const BackendConfig& config) {
  EXPECT_EQ(validate(config), std::nullopt);
  Backend backend(config);
  int updates = 0;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    backend.add_scan(d.scans[k]);
    if (backend.add_pose(d.utimes[k], d.input[k])) ++updates;
  }
  if (backend.finish()) ++updates;

  std::map<int64_t, std::size_t> index_of;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) index_of[d.utimes[k]] = k;
  const auto& keys = backend.key_poses();
  EXPECT_GT(keys.size(), 60u);  // a key pose every fourth 10 Hz pose (>= 333 ms)
  EXPECT_GE(updates, static_cast<int>(keys.size()));  // one per key pose (+1 at the end)
  std::vector<double> err_in, err_out;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const std::size_t k = index_of.at(keys[i].utime);
    err_in.push_back((d.input[k].translation() - d.truth[k].translation()).norm());
    err_out.push_back(
        (backend.key_poses()[i].T_world_base.translation() - d.truth[k].translation()).norm());
  }

  // Loops were closed on the second lap, none of them false: each agrees with the truth within
  // five standard deviations of its own covariance.
  EXPECT_GE(backend.closures().size(), 2u);
  for (const LoopClosure& c : backend.closures()) {
    const Pose2 T_true =
        between(d.truth[index_of.at(keys[c.from].utime)], d.truth[index_of.at(keys[c.to].utime)]);
    const Eigen::Vector3d e = edge_error(Pose2(), T_true, c.T_from_to);
    EXPECT_LT(std::sqrt(e.dot(c.covariance.inverse() * e)), 5.0) << c.from << " -> " << c.to;
  }
  // Marginals: the first key pose fixes the frame, the others are positive and grow away from it
  // until a loop closure ties them back.
  EXPECT_EQ(keys.front().covariance.norm(), 0.0);
  for (std::size_t i = 1; i < keys.size(); ++i) EXPECT_GT(keys[i].covariance(0, 0), 0.0);
  EXPECT_EQ(backend.counters().optimisations_failed, 0);
  // Key scans are kept at reduced density: well under the 1440 x 4 bytes of a raw sweep... in
  // points (8 bytes each), a few hundred per key pose.
  EXPECT_LT(backend.scans().bytes_per_key_pose(), 8.0 * 800);
  return {rms(err_in), rms(err_out)};
}

TEST(Backend, ClosesLoopsAndReducesTheErrorOfADriftingFrontend) {
  const test::Drive d = test::drive_ellipse(25.0);  // 1.7 laps of 14.5 m
  // Links by scan matching only: the matcher removes the frontend's drift between key poses.
  BackendConfig matching_only;
  matching_only.frontend_sigma_xy_m = 0.0;
  const auto [in, out] = run_drive(d, matching_only);
  EXPECT_GT(in, 0.3);  // [m] the input drifts
  EXPECT_LT(out, 0.25 * in);
  EXPECT_LT(out, 0.05);  // [m]
  // Links by matching and by the frontend's motion, declared with this frontend's real precision
  // (about 1.2 cm and 4 mrad per link): the graph's marginals then admit the closures.
  BackendConfig both;
  both.frontend_sigma_xy_m = 0.015;
  both.frontend_sigma_theta_rad = 0.005;
  const auto [in2, out2] = run_drive(d, both);
  EXPECT_LT(out2, 0.8 * in2);
}

TEST(Backend, SmoothsAFrontendJumpAway) {
  test::Drive d = test::drive_ellipse(6.0);
  for (auto& T : d.input) T = d.truth[&T - d.input.data()];  // a perfect frontend ...
  for (std::size_t k = 30; k < d.input.size(); ++k) d.input[k] = Pose2(0.6, -0.4, 0.0) * d.input[k];
  Backend backend{BackendConfig{}};  // ... that jumps at scan 30
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    backend.add_scan(d.scans[k]);
    backend.add_pose(d.utimes[k], d.input[k]);
  }
  backend.finish();
  EXPECT_EQ(backend.counters().prep.jumps_smoothed, 1);
  const int64_t utime = backend.key_poses().back().utime;
  const std::size_t k = static_cast<std::size_t>(
      std::find(d.utimes.begin(), d.utimes.end(), utime) - d.utimes.begin());
  ASSERT_LT(k, d.utimes.size());
  EXPECT_LT(
      (backend.key_poses().back().T_world_base.translation() - d.truth[k].translation()).norm(),
      0.05);
}

// Stamps that carry no time (a log whose first stamps are negative and whose others were printed
// to 10^4 s, so that runs of poses share one stamp): before, the backend's smoothing extrapolated
// 25 km steps from them, the correlative matcher sized its table by the result (std::bad_alloc)
// and the graph fell out of step with the scan store (SIGSEGV in BlockCholesky::set_pattern).
// Now a pose not later than the one before is dropped and counted, and the rest make a graph.
TEST(Backend, OddStampsAreDroppedAndCountedWithoutACrash) {
  const test::Drive d = test::drive_ellipse(8.0);
  Backend backend{BackendConfig{}};
  int64_t previous = 0;
  long repeated = 0;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    // The first five stamps negative, then 10^4 s steps every ten poses.
    const int64_t utime =
        k < 5 ? -5'000'000 + static_cast<int64_t>(k) * 1'000'000
              : 1'134'860'000'000'000 + static_cast<int64_t>(k / 10) * 10'000'000'000;
    if (k > 0 && utime <= previous) ++repeated;
    previous = utime;
    PlanarScan scan = d.scans[k];
    scan.utime_last = utime;
    scan.utime_first = utime - (d.scans[k].utime_last - d.scans[k].utime_first);
    backend.add_scan(scan);
    backend.add_pose(utime, d.input[k]);
  }
  backend.finish();
  EXPECT_EQ(backend.counters().prep.out_of_order, repeated);
  EXPECT_GT(repeated, 50);
  const auto& keys = backend.key_poses();
  ASSERT_GT(keys.size(), 3u);
  for (std::size_t i = 1; i < keys.size(); ++i) EXPECT_GT(keys[i].utime, keys[i - 1].utime);
  EXPECT_EQ(backend.counters().optimisations_failed, 0);
  for (const KeyPose& k : keys) EXPECT_LT(k.T_world_base.translation().norm(), 10.0);
}

// Stamps restamped from a log without time, one microsecond apart: a key pose by time would
// never come (before: one key pose of 80); by travel and turn they come as the platform moves.
// Stamps all equal: every pose after the first is out of order, and the backend says there is no
// trajectory instead of publishing a single key pose as a result.
TEST(Backend, StampsThatCarryNoTimeGiveKeyPosesByTravelOrAFault) {
  const test::Drive d = test::drive_ellipse(8.0);
  for (const int64_t spacing_us : {int64_t{1}, int64_t{0}}) {
    BackendConfig config;
    config.key_poses.distance_m = 0.5;
    config.key_poses.angle_rad = 0.35;
    Backend backend(config);
    for (std::size_t k = 0; k < d.utimes.size(); ++k) {
      const int64_t utime = 1'000'000 + static_cast<int64_t>(k) * spacing_us;
      PlanarScan scan = d.scans[k];
      scan.utime_first = scan.utime_last = utime;
      backend.add_scan(scan);
      backend.add_pose(utime, d.input[k]);
    }
    backend.finish();
    const auto& keys = backend.key_poses();
    if (spacing_us > 0) {
      EXPECT_EQ(backend.input_fault(), "");
      EXPECT_GT(keys.size(), 5u);
      EXPECT_EQ(backend.counters().optimisations_failed, 0);
      for (const KeyPose& k : keys) EXPECT_LT(k.T_world_base.translation().norm(), 10.0);
    } else {
      EXPECT_LE(keys.size(), 1u);
      EXPECT_EQ(backend.counters().prep.out_of_order, static_cast<long>(d.utimes.size()) - 1);
      EXPECT_NE(backend.input_fault().find("no trajectory"), std::string::npos)
          << backend.input_fault();
    }
  }
}

// A frontend that loses track: from scan 30 on its poses are off by 1.2 m and 0.6 rad (a wrong
// match it never undoes), with as small a covariance as before. Wheel odometry (here the truth
// with a 2 % scale error) contradicts that one step; the backend takes the odometry's step
// there, and the links match the scans around it. Without odometry the jump stays.
TEST(Backend, OdometryReplacesAFrontendStepItContradicts) {
  test::Drive d = test::drive_ellipse(8.0);
  for (std::size_t k = 0; k < d.input.size(); ++k) {
    d.input[k] = d.truth[k];
    if (k >= 30) d.input[k] = Pose2(1.2, 0.0, 0.6) * d.truth[k];
  }
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();
  const auto run = [&](bool odometry) {
    BackendConfig config;
    config.smoothing.input = "sparse";  // no jump smoothing: the step reaches the graph
    Backend backend(config);
    for (std::size_t k = 0; k < d.utimes.size(); ++k) {
      if (odometry) {
        const Pose2& T = d.truth[k];
        backend.add_odometry(d.utimes[k], Pose2(1.02 * T.x(), 1.02 * T.y(), T.theta()));
      }
      backend.add_scan(d.scans[k]);
      backend.add_pose(d.utimes[k], d.input[k], covariance);
    }
    backend.finish();
    // The last key pose against the truth, in the frame of the first (fixed at the truth).
    const KeyPose& last = backend.key_poses().back();
    const std::size_t k = static_cast<std::size_t>(
        std::find(d.utimes.begin(), d.utimes.end(), last.utime) - d.utimes.begin());
    EXPECT_LT(k, d.utimes.size());
    return std::pair{(last.T_world_base.translation() - d.truth[k].translation()).norm(),
                     backend.counters().frontend_steps_replaced};
  };
  const auto [error_without, replaced_without] = run(false);
  const auto [error_with, replaced_with] = run(true);
  EXPECT_EQ(replaced_without, 0);
  EXPECT_EQ(replaced_with, 1);
  EXPECT_GT(error_without, 0.5);  // [m]
  EXPECT_LT(error_with, 0.05);    // [m]
}

// A frontend that drifts 0.8 m over 6 s and then snaps back to its map in one step when it comes
// back to ground it mapped (aces from a heading 1 mrad off: 1.19 m in 0.24 s). The odometry (the
// truth) contradicts the snap and takes its place, which keeps the drift; the loop the drive
// closes afterwards must still be able to take it out. The replacing edges carry the two steps'
// difference as covariance: without it the graph is sure of the drifted pose and refuses the
// closures as contradicting it, and the run ends 0.8 m off.
TEST(Backend, AClosureCanUndoWhatTheOdometryKeptOfAFrontendsSnapBack) {
  test::Drive d = test::drive_ellipse(25.0);       // the start is passed again from about 14.5 s on
  const std::size_t drift_begin = 60, snap = 120;  // 6 s and 12 s
  d.input = d.truth;
  for (std::size_t k = drift_begin; k < snap; ++k) {
    d.input[k] =
        Pose2(0.8 * static_cast<double>(k - drift_begin) / (snap - drift_begin), 0.0, 0.0) *
        d.truth[k];
  }
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();
  BackendConfig config;
  config.smoothing.input = "sparse";  // no jump smoothing: the snap reaches the graph
  Backend backend(config);
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    backend.add_odometry(d.utimes[k], d.truth[k]);
    backend.add_scan(d.scans[k]);
    backend.add_pose(d.utimes[k], d.input[k], covariance);
  }
  backend.finish();
  EXPECT_GE(backend.counters().frontend_steps_replaced, 1);
  EXPECT_GE(backend.closures().size(), 1u);
  const KeyPose& last = backend.key_poses().back();
  const std::size_t k = static_cast<std::size_t>(
      std::find(d.utimes.begin(), d.utimes.end(), last.utime) - d.utimes.begin());
  ASSERT_LT(k, d.utimes.size());
  const double error_m = (last.T_world_base.translation() - d.truth[k].translation()).norm();
  std::printf("last key pose against the truth: %.4f m (replaced %ld, closures %ld)\n", error_m,
              static_cast<long>(backend.counters().frontend_steps_replaced),
              static_cast<long>(backend.closures().size()));
  EXPECT_LT(error_m, 0.1);  // [m]
}

// A frontend whose pose is off by 0.4 m for a few scans around one key pose and right again after
// (Kummerle's fr079 at 2109.7 s: 0.436 m forward, 0.261 m back), while the wheels slip by 5 cm
// over the same interval. The odometry contradicts both key steps around the spike. It places the
// spike's key pose; the step after takes the frontend's net motion over both, which agrees with
// the odometry's, so the slip stays out. Before, the odometry replaced both steps and its slip
// moved the rest of the run by 5 cm.
TEST(Backend, OdometryOverAFrontendSpikeKeepsTheFrontendsNetMotion) {
  test::Drive d = test::drive_ellipse(8.0);
  const std::size_t spike_begin = 40, spike_end = 44;  // 0.4 s: one key pose's scan among them
  d.input = d.truth;
  for (std::size_t k = spike_begin; k < spike_end; ++k) d.input[k] = d.truth[k] * Pose2(0.4, 0, 0);
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-5).asDiagonal();
  BackendConfig config;
  config.smoothing.input = "sparse";  // no jump smoothing: the spike reaches the graph
  // The frontend's chain and the odometry alone (no link edges, no closures), so that what the
  // graph makes of the two steps is all that moves the rest of the run.
  config.min_link_response = 1.0;
  config.loop.min_travel_m = 1e5;
  Backend backend(config);
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    // The odometry is the truth, slipped 5 cm back over the spike's scans and after.
    const double slip = k < spike_begin ? 0.0 : -0.05 * std::min(1.0, (k - spike_begin) / 4.0);
    backend.add_odometry(d.utimes[k], d.truth[k] * Pose2(slip, 0.0, 0.0));
    backend.add_scan(d.scans[k]);
    backend.add_pose(d.utimes[k], d.input[k], covariance);
  }
  backend.finish();
  EXPECT_EQ(backend.counters().frontend_steps_replaced, 1);
  EXPECT_EQ(backend.counters().frontend_spikes_netted, 1);
  // The key poses after the spike where the frontend put them: within 1 cm of the truth (with
  // both steps replaced, 4-5 cm off).
  double largest_after_m = 0.0;
  for (const KeyPose& key : backend.key_poses()) {
    const std::size_t k = static_cast<std::size_t>(
        std::find(d.utimes.begin(), d.utimes.end(), key.utime) - d.utimes.begin());
    ASSERT_LT(k, d.utimes.size());
    if (k < spike_end) continue;
    largest_after_m = std::max(largest_after_m,
                               (key.T_world_base.translation() - d.truth[k].translation()).norm());
  }
  std::printf("key poses after the spike against the truth: largest error %.4f m\n",
              largest_after_m);
  EXPECT_LT(largest_after_m, 0.01);
}

// Odometry whose readings lag (Kummerle's intel: ODOM stamps in bursts) contradicts a right
// frontend step by 0.15 m; the link matched around the odometry's step ends where the one around
// the frontend's did, with a response higher by the grid's luck. Before, that response alone
// replaced the frontend's step, and the rest of intel's run turned by 1.5 degrees; the scans side
// with the odometry only where their match lies at its step and away from the frontend's.
TEST(OdometryCheck, ScansSideWithTheOdometryOnlyWhereTheirMatchLiesAtItsStep) {
  OdometryStep odometry;
  odometry.motion = Pose2(0.012, 0.0, 0.0);
  odometry.covariance = Eigen::Vector3d(4e-4, 4e-4, 4e-4).asDiagonal();
  const Pose2 frontend(0.163, -0.006, 0.004);
  const Eigen::Matrix3d frontend_covariance = Eigen::Vector3d(1e-5, 1e-5, 1e-6).asDiagonal();
  const Eigen::Matrix3d match_covariance = Eigen::Vector3d(2e-4, 2e-4, 4e-5).asDiagonal();
  const double gate = OdometryCheckConfig{}.max_frontend_chi2;
  // The match at the frontend's step: no verdict for the odometry, however it scores.
  EXPECT_FALSE(scans_side_with_odometry(odometry, frontend, frontend_covariance,
                                        Pose2(0.155, 0.002, 0.0), match_covariance, 0.81, 0.80,
                                        gate));
  // At the odometry's step and scoring better: the scans side with it.
  EXPECT_TRUE(scans_side_with_odometry(odometry, frontend, frontend_covariance,
                                       Pose2(0.02, 0.0, 0.0), match_covariance, 0.81, 0.80, gate));
  // ... but not scoring better.
  EXPECT_FALSE(scans_side_with_odometry(odometry, frontend, frontend_covariance,
                                        Pose2(0.02, 0.0, 0.0), match_covariance, 0.79, 0.80, gate));
}

TEST(OdometryCheck, InterpolatesBetweenReadingsAndKnowsItsGaps) {
  OdometryCheck check{OdometryCheckConfig{}};
  check.add(1'000'000, Pose2(0.0, 0.0, 0.0));
  check.add(1'100'000, Pose2(0.1, 0.0, 0.0));
  check.add(1'100'000, Pose2(9.0, 0.0, 0.0));  // not later: dropped
  check.add(3'000'000, Pose2(0.2, 0.0, 0.0));  // 1.9 s later: nothing known between
  EXPECT_EQ(check.counters().readings_out_of_order, 1);
  const Eigen::Matrix3d none = Eigen::Matrix3d::Zero();
  const auto step = check.check(1'000'000, 1'050'000, Pose2(0.05, 0.0, 0.0), none);
  ASSERT_TRUE(step);
  EXPECT_NEAR(step->motion.x(), 0.05, 1e-9);
  EXPECT_FALSE(step->frontend_rejected);
  const auto jump = check.check(1'000'000, 1'050'000, Pose2(0.55, 0.0, 0.0), none);
  ASSERT_TRUE(jump);
  EXPECT_TRUE(jump->frontend_rejected);
  EXPECT_FALSE(check.check(1'000'000, 2'000'000, Pose2(), none));  // inside the gap
  EXPECT_FALSE(check.check(0, 1'000'000, Pose2(), none));          // 1 s before the first reading
}

// Readings whose stamps do not follow the motion (Kummerle's intel: a burst of readings 3 cm
// apart stamped within a millisecond, after half a second without any) say nothing about the
// steps around them: those are not checked, and counted. Steps clear of them still are.
TEST(OdometryCheck, StepsNearReadingsOfImplausibleSpeedAreNotChecked) {
  OdometryCheck check{OdometryCheckConfig{}};
  for (int i = 0; i <= 20; ++i) check.add(1'000'000 + i * 100'000, Pose2(0.03 * i, 0.0, 0.0));
  EXPECT_EQ(check.counters().readings_implausible, 0);
  check.add(3'000'200, Pose2(0.63, 0.0, 0.0));  // 3 cm in 0.2 ms: 150 m/s
  check.add(3'000'400, Pose2(0.66, 0.0, 0.0));
  check.add(3'100'000, Pose2(0.69, 0.0, 0.0));
  check.add(3'200'000, Pose2(0.72, 0.0, 0.0));
  check.add(3'200'100, Pose2(0.72, 0.0, 1.0));  // a turn of 1 rad in 0.1 ms
  EXPECT_EQ(check.counters().readings_implausible, 3);
  const Eigen::Matrix3d none = Eigen::Matrix3d::Zero();
  EXPECT_FALSE(check.check(2'800'000, 3'100'000, Pose2(0.09, 0.0, 0.0), none));
  EXPECT_FALSE(check.check(2'300'000, 2'600'000, Pose2(0.09, 0.0, 0.0), none));  // 0.4 s before
  EXPECT_EQ(check.counters().steps_implausible, 2);
  const auto clear = check.check(1'000'000, 1'300'000, Pose2(0.09, 0.0, 0.0), none);
  ASSERT_TRUE(clear);
  EXPECT_NEAR(clear->motion.x(), 0.09, 1e-9);
  EXPECT_EQ(check.counters().steps_checked, 1);
}

TEST(Backend, ConfigValidation) {
  BackendConfig config;
  EXPECT_EQ(validate(config), std::nullopt);
  config.link.resolution_m = -1.0;
  ASSERT_TRUE(validate(config));
  EXPECT_NE(validate(config)->find("key 'link."), std::string::npos);
  config = BackendConfig{};
  config.optimize_every = 0;
  EXPECT_TRUE(validate(config));
  // A key pose at least every 0 or -1 us is no interval.
  for (const int64_t interval_us : {0, -1}) {
    config = BackendConfig{};
    config.key_poses.interval_us = interval_us;
    ASSERT_TRUE(validate(config));
    EXPECT_NE(validate(config)->find("key 'key_poses.interval_us'"), std::string::npos);
  }
}

}  // namespace
}  // namespace traverse::backend
