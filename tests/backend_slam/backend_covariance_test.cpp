// What the backend publishes as each key pose's covariance (Backend::published_covariance): the
// terms no edge holds, and the marginals made with the frontend's chain at marginal_frontend_scale.
#include <gtest/gtest.h>

#include <cstdio>

#include "backend.hpp"
#include "synthetic.hpp"

namespace traverse::backend {
namespace {

// The graph's marginals scaled (marginal_scale), the frame's heading and each key pose's own error
// (frame_heading_sigma_rad, key_pose_sigma_xy_m) added: in the published marginals and nowhere
// else; the optimum and the graph's own marginals (which the loop closer's check uses) stay as
// they were.
TEST(Backend, PublishedCovarianceAddsTheFramesHeadingAndTheKeyPosesOwnError) {
  const test::Drive d = test::drive_ellipse(6.0);
  BackendConfig plain;
  BackendConfig reported = plain;
  reported.frame_heading_sigma_rad = 0.004;
  reported.key_pose_sigma_xy_m = 0.01;
  reported.marginal_scale = 50.0;
  ASSERT_EQ(validate(reported), std::nullopt);
  Backend a(plain), b(reported);
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    a.add_scan(d.scans[k]);
    a.add_pose(d.utimes[k], d.input[k]);
    b.add_scan(d.scans[k]);
    b.add_pose(d.utimes[k], d.input[k]);
  }
  a.finish();
  b.finish();
  ASSERT_EQ(a.key_poses().size(), b.key_poses().size());
  ASSERT_GT(a.key_poses().size(), 10u);
  EXPECT_EQ(b.published_covariance(0).norm(), 0.0);  // the first key pose fixes the frame
  const Eigen::Vector2d t0 = b.key_poses()[0].T_world_base.translation();
  for (std::size_t i = 1; i < b.key_poses().size(); ++i) {
    const KeyPose& ka = a.key_poses()[i];
    const KeyPose& kb = b.key_poses()[i];
    EXPECT_EQ((ka.T_world_base.translation() - kb.T_world_base.translation()).norm(), 0.0);
    EXPECT_EQ((ka.covariance - kb.covariance).norm(), 0.0);
    EXPECT_EQ((a.published_covariance(static_cast<int>(i)) - ka.covariance).norm(), 0.0);
    // A turn of the frame moves key pose i across the line from the first key pose: its
    // variance that way grows by (sigma r)^2, along the line by nothing; both by the key pose's
    // own (1 cm)^2; its heading by sigma^2.
    const Eigen::Matrix3d added =
        b.published_covariance(static_cast<int>(i)) - 50.0 * kb.covariance;
    const Eigen::Vector2d r = kb.T_world_base.translation() - t0;
    if (r.norm() < 0.1) continue;  // [m] no direction yet
    const Eigen::Vector2d across = Eigen::Vector2d(-r.y(), r.x()).normalized();
    const Eigen::Vector2d along = r.normalized();
    const Eigen::Matrix2d P = added.topLeftCorner<2, 2>();
    EXPECT_NEAR(across.dot(P * across), 0.004 * 0.004 * r.squaredNorm() + 1e-4, 1e-12);
    EXPECT_NEAR(along.dot(P * along), 1e-4, 1e-12);
    EXPECT_NEAR(added(2, 2), 0.004 * 0.004, 1e-15);
  }
}

// A frontend that claims far more than it holds (the office cart's fallback sigmas, 1 mm and
// 5e-6 rad, with the drift model): in the graph as optimised its chain outweighs every closure, so
// a closure leaves the key poses' marginals as they were, and scaled after the fact
// (marginal_scale) they stay as large after it. With the chain's edges at marginal_frontend_scale
// the marginals are made from a graph in which a closure weighs what it measures: the key poses
// it ties back get smaller marginals. Neither the optimum nor the graph's own marginals (the loop
// closer's) move.
TEST(Backend, AClosureLowersTheCalibratedMarginalsNearIt) {
  test::Drive d = test::drive_ellipse(25.0);
  d.input = d.truth;  // the frontend is right; it only claims too much
  BackendConfig plain;
  plain.frontend_sigma_xy_m = 0.001;
  plain.frontend_sigma_theta_rad = 5e-6;
  plain.frontend_drift_length_m = 20.0;
  BackendConfig calibrated = plain;
  calibrated.marginal_frontend_scale = 400.0;
  ASSERT_EQ(validate(calibrated), std::nullopt);
  Backend a(plain), b(calibrated);
  // The published covariance's trace of position of key pose i [m^2].
  const auto trace = [](const Backend& backend, int i) {
    return backend.published_covariance(i).topLeftCorner<2, 2>().trace();
  };
  struct Drop {
    double plain = 0.0, calibrated = 0.0;  // after / before, at the key pose the closure ends on
    int closures = 0;
  } drop;
  for (std::size_t k = 0; k < d.utimes.size(); ++k) {
    a.add_scan(d.scans[k]);
    b.add_scan(d.scans[k]);
    const int keys_before = static_cast<int>(b.key_poses().size());
    std::vector<double> before_a, before_b;
    for (int i = 0; i < keys_before; ++i) {
      before_a.push_back(trace(a, i));
      before_b.push_back(trace(b, i));
    }
    const auto ua = a.add_pose(d.utimes[k], d.input[k]);
    const auto ub = b.add_pose(d.utimes[k], d.input[k]);
    ASSERT_EQ(ua.has_value(), ub.has_value());
    if (!ub || ub->new_closures.empty() || drop.closures > 0) continue;
    ASSERT_EQ(ua->new_closures.size(), ub->new_closures.size());
    // The closure's newer key pose had a marginal before it (it ends on an older key pose).
    const int i = ub->new_closures.front().to;
    ASSERT_LT(i, keys_before);
    drop.plain = trace(a, i) / before_a[i];
    drop.calibrated = trace(b, i) / before_b[i];
    ++drop.closures;
  }
  a.finish();
  b.finish();
  ASSERT_EQ(drop.closures, 1);
  std::printf(
      "the first closure's key pose: position variance after / before %.3f (graph's own), "
      "%.3f (frontend's chain at 400 for the marginals)\n",
      drop.plain, drop.calibrated);
  EXPECT_GT(drop.plain, 0.9) << "the over-confident chain outweighs the closure";
  EXPECT_LT(drop.calibrated, 0.5) << "the closure lowers the calibrated marginal";
  ASSERT_EQ(a.key_poses().size(), b.key_poses().size());
  for (std::size_t i = 0; i < a.key_poses().size(); ++i) {
    const KeyPose& ka = a.key_poses()[i];
    const KeyPose& kb = b.key_poses()[i];
    EXPECT_EQ((ka.T_world_base.translation() - kb.T_world_base.translation()).norm(), 0.0);
    EXPECT_EQ((ka.covariance - kb.covariance).norm(), 0.0);
  }
}

}  // namespace
}  // namespace traverse::backend
