// The backend's boresight estimate (processes/backend/boresight.hpp) on a graph built from a cart
// whose horizontal scanner is turned on it: the frontend tracks the base turned by the scanner's
// yaw, and the backend publishes the trajectory turned back, every key pose by the same yaw.
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
// tracks (the base turned by kDelta), without error, in a map frame at the first pose.
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

TurnedDrive turned_drive() {
  std::mt19937 rng(11);
  TurnedDrive d;
  test::synthetic::SweepSpec spec;
  spec.n_ranges = 1440;
  spec.angle_first = -M_PI;
  spec.angle_step = 2.0 * M_PI / spec.n_ranges;
  spec.range_max = 20.0;
  spec.noise_sigma_m = 0.005;
  const Pose2 R(0.0, 0.0, kDelta);
  const Pose2 T0_inverse = corridor_pose(spec.duration_us).inverse();
  for (int64_t t0 = 0; t0 < 26000000; t0 += 100000) {
    spec.utime_first = t0;
    PlanarScan scan =
        test::synthetic::make_sweep(test::irregular_corridor(), corridor_pose, R, spec, &rng);
    d.utimes.push_back(scan.utime_last);
    d.truth.push_back(T0_inverse * corridor_pose(scan.utime_last));
    d.input.push_back(R.inverse() * d.truth.back() * R);
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

TEST(BackendBoresight, ConfigValidationNamesTheKey) {
  BackendConfig c;
  c.boresight.chord_m = -1.0;
  const auto problem = validate(c);
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("boresight.chord_m"), std::string::npos) << *problem;
}

}  // namespace
}  // namespace traverse::backend
