// The backend's boresight estimate (processes/backend/boresight.hpp) on a graph built from a cart
// whose horizontal scanner is turned on it: the frontend tracks the base turned by the scanner's
// yaw, and the backend publishes the trajectory turned back, every key pose by the same yaw. And
// the frontend's map held against the first key scan (processes/backend/start_frame.hpp): where
// the map turned while it was built (its grid held the walls), the backend measures that turn and
// takes it out before the boresight's.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "backend.hpp"
#include "cart_path.hpp"
#include "synthetic.hpp"

namespace traverse::backend {
namespace {

constexpr double kDelta = 0.004;  // [rad] the scanner's true yaw on the cart (0.23 deg)

// A cart weaving along the irregular corridor at about 1 m/s, heading along its path, one sweep
// every 100 ms from the scanner turned by kDelta; the frontend's poses are those of the frame it
// tracks (the base turned by kDelta), without error, in a map frame at the first pose. With
// `held`, the frontend's map turned by kDelta in the first second instead (a grid that holds the
// walls on its axes): its positions are the base's, its headings the scanner's (kDelta more,
// growing from 0 at the first pose over `turn_s` seconds).
struct TurnedDrive {
  std::vector<int64_t> utimes;
  std::vector<Pose2> truth;  // T_map_base, the map frame at the first pose
  std::vector<Pose2> input;  // T_map_bhat
  std::vector<PlanarScan> scans;
};

Pose2 corridor_pose(int64_t utime) {
  const double x = -13.0 + 1e-6 * static_cast<double>(utime);
  return Pose2(x, 0.25 * std::sin(0.4 * x), std::atan(0.1 * std::cos(0.4 * x)));
}

TurnedDrive turned_drive(bool held = false, double turn_s = 1.0) {
  std::mt19937 rng(11);
  TurnedDrive d;
  test::synthetic::SweepSpec spec = test::full_sweep_spec();
  const Pose2 R(0.0, 0.0, kDelta);
  const Pose2 T0_inverse = corridor_pose(spec.duration_us).inverse();
  for (int64_t t0 = 0; t0 < 26000000; t0 += 100000) {
    spec.utime_first = t0;
    PlanarScan scan =
        test::synthetic::make_sweep(test::irregular_corridor(), corridor_pose, R, spec, &rng);
    d.utimes.push_back(scan.utime_last);
    d.truth.push_back(T0_inverse * corridor_pose(scan.utime_last));
    if (held) {
      const Pose2& T = d.truth.back();
      const double turned = kDelta * std::min(1.0, 1e-6 * static_cast<double>(t0) / turn_s);
      d.input.push_back(Pose2(T.x(), T.y(), T.theta() + turned));
    } else {
      d.input.push_back(R.inverse() * d.truth.back() * R);
    }
    d.scans.push_back(std::move(scan));
  }
  return d;
}

// Runs the drive through a backend; returns the largest position error [m] of the key poses as
// published and as the graph holds them.
std::pair<double, double> run(const TurnedDrive& d, Backend& backend) {
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    backend.add_scan(d.scans[k]);
    backend.add_pose(d.utimes[k], d.input[k]);
  }
  backend.finish();
  std::map<int64_t, std::size_t> index_of;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) index_of[d.utimes[k]] = k;
  double published = 0.0, graph = 0.0;
  for (std::size_t i = 0; i < backend.key_poses().size(); ++i) {
    const Pose2& truth = d.truth[index_of.at(backend.key_poses()[i].utime)];
    const Pose2 T = backend.published_pose(static_cast<int>(i));
    published = std::max(published, (T.translation() - truth.translation()).norm());
    graph = std::max(
        graph, (backend.key_poses()[i].T_world_base.translation() - truth.translation()).norm());
  }
  return {published, graph};
}

// Off, the graph comes out turned by the scanner's yaw about the first key pose (26 m of travel:
// 10 cm across at the end) and is published so. On, the yaw is estimated from the key poses and
// every published key pose is the graph's turned back by that one yaw: within a centimetre of the
// truth; the frame's heading term of the published covariance is the estimate's sigma.
TEST(BackendBoresight, AGraphFromATurnedScannerIsPublishedTurnedBack) {
  const TurnedDrive d = turned_drive();
  BackendConfig off;
  off.frame_heading_sigma_rad = 0.0036;
  Backend plain(off);
  const auto [published_off, graph_off] = run(d, plain);
  EXPECT_GT(graph_off, 0.08);
  EXPECT_EQ(published_off, graph_off);
  EXPECT_FALSE(plain.boresight().yaw_rad().has_value());

  BackendConfig on = off;
  on.boresight.enabled = true;
  ASSERT_EQ(validate(on), std::nullopt);
  Backend backend(on);
  const auto [published_on, graph_on] = run(d, backend);
  EXPECT_NEAR(graph_on, graph_off, 0.005);  // the graph itself is the same
  ASSERT_TRUE(backend.boresight().yaw_rad().has_value());
  const double yaw = *backend.boresight().yaw_rad();
  EXPECT_NEAR(yaw, kDelta, 5e-4);
  // 26 m of key poses: the chords' scatter about the fit (the weave sampled every third of a
  // metre) gives about a milliradian.
  EXPECT_GT(backend.boresight().yaw_sigma_rad(), std::abs(yaw - kDelta) / 3.0);
  EXPECT_LT(backend.boresight().yaw_sigma_rad(), 2e-3);
  EXPECT_LT(published_on, 0.015) << "yaw " << yaw << " +- " << backend.boresight().yaw_sigma_rad();
  EXPECT_LT(published_on, 0.2 * graph_off);

  // One yaw for every key pose: each published position is the graph's turned by it about the
  // first key pose, the heading as optimised.
  const std::vector<KeyPose>& keys = backend.key_poses();
  const Eigen::Vector2d p0 = keys[0].T_world_base.translation();
  for (std::size_t i = 1; i < keys.size(); ++i) {
    const Pose2 T = backend.published_pose(static_cast<int>(i));
    const Eigen::Vector2d a = keys[i].T_world_base.translation() - p0, b = T.translation() - p0;
    EXPECT_NEAR(a.norm(), b.norm(), 1e-9);
    EXPECT_EQ(T.theta(), keys[i].T_world_base.theta());
    if (a.norm() < 1.0) continue;
    EXPECT_NEAR(std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)), yaw, 1e-9) << i;
    // The frame's heading term: the estimate's sigma in place of the configured 0.0036 rad.
    const Eigen::Vector2d across = Eigen::Vector2d(-b.y(), b.x()).normalized();
    const Eigen::Matrix2d P =
        backend.published_covariance(static_cast<int>(i)).topLeftCorner<2, 2>();
    const Eigen::Matrix2d P_off =
        plain.published_covariance(static_cast<int>(i)).topLeftCorner<2, 2>();
    EXPECT_LT(across.dot(P * across), across.dot(P_off * across));
  }
}

// A rig file that is right is left as it is: an estimate within min_sigmas of zero is not applied
// (key poses a third of a metre apart along 84 m, 2 mm of noise), one of 0.003 rad is.
TEST(BackendBoresight, AppliedOnlyWhenItDiffersFromTheRigFile) {
  BoresightConfig config;
  config.enabled = true;
  for (const double delta : {0.0, 0.003}) {
    Boresight boresight(config);
    boresight.update(
        traverse::test::as_tracked(traverse::test::cart_path(0.33, 0.0), delta, 0.002, 9));
    EXPECT_GT(boresight.travel_m(), 50.0);
    EXPECT_LT(std::abs(boresight.estimate_rad() - delta), 5e-4) << delta;
    EXPECT_EQ(boresight.yaw_rad().has_value(), delta != 0.0) << boresight.estimate_rad();
    const Pose2 T(10.0, 0.0, 0.3);
    const Pose2 published = boresight.published(T, Pose2());
    EXPECT_NEAR(published.y(), 10.0 * std::sin(boresight.yaw_rad().value_or(0.0)), 1e-12);
  }
  config.min_sigmas = 0.0;  // every estimate applied
  Boresight any(config);
  any.update(traverse::test::as_tracked(traverse::test::cart_path(0.33, 0.0), 0.0, 0.002, 9));
  EXPECT_TRUE(any.yaw_rad().has_value());
}

// The map held on the grid's axes: the chords run at -kDelta from the headings as when the whole
// map turned, so the boresight alone turns right positions wrong (10 cm at 26 m). The first key
// scan, matched by the key scans 2-8 m along, shows the map's turn; taken out first, the published
// key poses are within a centimetre and a milliradian of the truth.
TEST(BackendStartFrame, AMapTheGridHeldIsNotTurnedByTheBoresight) {
  const TurnedDrive d = turned_drive(/*held=*/true);
  BackendConfig config;
  config.boresight.enabled = true;
  Backend boresight_only(config);
  const auto [published_boresight, graph] = run(d, boresight_only);
  EXPECT_LT(graph, 0.03);  // the links near the first key pose see the map turn
  EXPECT_GT(published_boresight, 0.07);

  config.start_frame.enabled = true;
  ASSERT_EQ(validate(config), std::nullopt);
  Backend backend(config);
  const auto [published, graph_again] = run(d, backend);
  EXPECT_EQ(graph_again, graph);  // nothing the graph holds changes
  ASSERT_TRUE(backend.start_frame().heading_rad().has_value());
  EXPECT_NEAR(*backend.start_frame().heading_rad(), kDelta, 5e-4);
  EXPECT_GE(backend.start_frame().matches(), 10);
  EXPECT_LT(published, 0.015);
  std::map<int64_t, std::size_t> index_of;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) index_of[d.utimes[k]] = k;
  const std::vector<KeyPose>& keys = backend.key_poses();
  EXPECT_EQ(backend.published_pose(0).theta(), keys[0].T_world_base.theta());
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (keys[i].utime < 1000000) continue;  // the map still turning
    const Pose2& truth = d.truth[index_of.at(keys[i].utime)];
    EXPECT_LT(
        std::abs(wrap_angle(backend.published_pose(static_cast<int>(i)).theta() - truth.theta())),
        1e-3)
        << i;
  }
}

// Where the whole map turned with the scanner (the first key scan agrees with the map), the turn
// measured is near zero and none is taken out: the boresight alone publishes the trajectory.
TEST(BackendStartFrame, AMapInTheFirstScansFrameIsLeftAsItIs) {
  const TurnedDrive d = turned_drive();
  BackendConfig config;
  config.boresight.enabled = true;
  Backend boresight_only(config);
  const auto [published_boresight, graph] = run(d, boresight_only);
  config.start_frame.enabled = true;
  Backend backend(config);
  const auto [published, graph_again] = run(d, backend);
  EXPECT_GE(backend.start_frame().matches(), 10);
  EXPECT_LT(std::abs(backend.start_frame().estimate_rad()), 5e-4);
  EXPECT_FALSE(backend.start_frame().heading_rad().has_value());
  EXPECT_EQ(published, published_boresight);
  EXPECT_LT(published, 0.015);
}

// A map that drifts away from the first scan over the first 8 m (its headings turn by kDelta
// evenly over them) is no turn the grid gave it at once: the early matches see a tenth of it, and
// nothing is taken out.
TEST(BackendStartFrame, AGradualDriftIsNotTakenForTheGridsTurn) {
  const TurnedDrive d = turned_drive(/*held=*/true, /*turn_s=*/8.0);
  BackendConfig config;
  config.boresight.enabled = true;
  config.start_frame.enabled = true;
  Backend backend(config);
  run(d, backend);
  EXPECT_GE(backend.start_frame().matches(), 10);
  EXPECT_GT(std::abs(backend.start_frame().estimate_rad()), 1.5e-3);
  EXPECT_LT(std::abs(backend.start_frame().early_estimate_rad()),
            0.5 * std::abs(backend.start_frame().estimate_rad()));
  EXPECT_FALSE(backend.start_frame().heading_rad().has_value());
}

TEST(BackendBoresight, ConfigValidationNamesTheKey) {
  BackendConfig c;
  c.boresight.chord_m = -1.0;
  const auto problem = validate(c);
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("boresight.chord_m"), std::string::npos) << *problem;
  c = BackendConfig();
  c.start_frame.max_travel_m = 1.0;  // below min_travel_m
  const auto frame = validate(c);
  ASSERT_TRUE(frame.has_value());
  EXPECT_NE(frame->find("start_frame.max_travel_m"), std::string::npos) << *frame;
}

}  // namespace
}  // namespace traverse::backend
