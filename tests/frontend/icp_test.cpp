// The ICP frontend (processes/frontend/icp/): the point-to-line matcher from seeded perturbed
// starts, its covariance (units and consistency), and the whole frontend on a walk through the
// synthetic room.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>

#include "hector/scan_points.hpp"
#include "icp/icp_matcher.hpp"
#include "icp/point_map.hpp"
#include "synthetic_scans.hpp"
#include "test_scans.hpp"

namespace traverse::frontend {
namespace {

using testing::static_scan;

// The map of one noise-free full-circle scan of the room taken at T_world_base.
PointMap room_map(const Pose2& T_world_base, const IcpConfig& c) {
  const auto points = static_scan(synthetic::room(), T_world_base, 2880);
  const auto kept = subsample(points, c.point_spacing_m);
  const auto normals = scan_normals(kept, c.normal_radius_m, c.max_line_spread);
  std::vector<MapPoint> map_points;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (normals[i]) {
      map_points.push_back(MapPoint{T_world_base * kept[i], T_world_base.rotation() * *normals[i]});
    }
  }
  PointMap map(c.cell_m, c.point_spacing_m);
  map.add(map_points);
  return map;
}

Eigen::Matrix3d weak_prior(const IcpConfig& c) {
  return Eigen::Vector3d(std::pow(c.prior_sigma_xy_m, -2), std::pow(c.prior_sigma_xy_m, -2),
                         std::pow(c.prior_sigma_theta_rad, -2))
      .asDiagonal();
}

TEST(IcpMatcher, ConvergesFromSeededPerturbedStarts) {
  const IcpConfig c;
  const PointMap map = room_map(Pose2(-1.0, 0.5, 0.3), c);
  const Pose2 T_true(-0.8, 0.6, 0.35);
  const auto query =
      subsample(static_scan(synthetic::room(), T_true, 1440, 0.002, 7), c.query_spacing_m);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> xy(-0.1, 0.1), th(-0.05, 0.05);
  for (int k = 0; k < 20; ++k) {
    const Pose2 start(T_true.x() + xy(rng), T_true.y() + xy(rng), T_true.theta() + th(rng));
    const IcpResult r = match_point_to_line(map, query, start, start, weak_prior(c), c);
    EXPECT_TRUE(r.converged) << "start " << k << " iterations " << r.iterations;
    EXPECT_LT((r.T_map_base.translation() - T_true.translation()).norm(), 0.003) << "start " << k;
    EXPECT_LT(std::abs(wrap_angle(r.T_map_base.theta() - T_true.theta())), 0.001) << "start " << k;
    EXPECT_GT(r.inlier_fraction, 0.9);
  }
}

// The covariance is sigma^2 (J^T W J)^-1: with twice the range noise its variances grow four
// times (m^2 and rad^2, not a Hessian, which would not move), and against the errors of many
// noisy scans its normalised error is that of a consistent estimate (mean NEES 3 for 3 degrees of
// freedom).
TEST(IcpMatcher, CovarianceHasTheUnitsAndSizeOfTheError) {
  IcpConfig c;
  c.min_residual_sigma_m = 1e-5;  // the floor would hide the noise's scale
  const PointMap map = room_map(Pose2(-1.0, 0.5, 0.3), c);
  const Pose2 T_true(-0.9, 0.55, 0.32);
  const auto run = [&](double noise_m, int scans, double* nees) {
    Eigen::Vector3d variances = Eigen::Vector3d::Zero();
    double nees_sum = 0.0;
    for (int k = 0; k < scans; ++k) {
      const auto query = subsample(static_scan(synthetic::room(), T_true, 1440, noise_m, 100 + k),
                                   c.query_spacing_m);
      const IcpResult r = match_point_to_line(map, query, T_true, T_true, weak_prior(c), c);
      const Eigen::Vector3d e(r.T_map_base.x() - T_true.x(), r.T_map_base.y() - T_true.y(),
                              wrap_angle(r.T_map_base.theta() - T_true.theta()));
      nees_sum += e.dot(r.covariance.ldlt().solve(e));
      variances += r.covariance.diagonal();
    }
    if (nees) *nees = nees_sum / scans;
    return Eigen::Vector3d(variances / scans);
  };
  double nees = 0.0;
  const Eigen::Vector3d v1 = run(0.005, 100, &nees);
  const Eigen::Vector3d v2 = run(0.010, 20, nullptr);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(v2[i] / v1[i], 3.0) << i;
    EXPECT_LT(v2[i] / v1[i], 5.0) << i;
  }
  // Position standard deviation of a 5 mm-noise scan of a room: sub-millimetre, not metres.
  EXPECT_LT(std::sqrt(v1[0]), 0.002);
  EXPECT_GT(std::sqrt(v1[0]), 1e-5);
  EXPECT_GT(nees, 1.5);
  EXPECT_LT(nees, 6.0);
}

TEST(PointMap, KeepsOnePointPerSpacingAndDropsFarCells) {
  PointMap map(0.3, 0.03);
  const Eigen::Vector2d n(1.0, 0.0);
  EXPECT_EQ(map.add({MapPoint{{0.0, 0.0}, n}, MapPoint{{0.01, 0.0}, n}, MapPoint{{0.1, 0.0}, n}}),
            2);
  EXPECT_NE(map.nearest({0.09, 0.01}, 0.05), nullptr);
  EXPECT_EQ(map.nearest({0.5, 0.5}, 0.05), nullptr);
  map.add({MapPoint{{50.0, 0.0}, n}});
  EXPECT_EQ(map.points(), 3u);
  EXPECT_EQ(map.drop_beyond({50.0, 0.0}, 10.0), 1);
  EXPECT_EQ(map.points(), 1u);
}

TEST(ScanNormals, AreUnitNormalsOfTheLineAndNoneAtACorner) {
  std::vector<Eigen::Vector2d> wall;
  for (int i = 0; i < 20; ++i) wall.emplace_back(1.0, -0.2 + 0.02 * i);
  const auto normals = scan_normals(wall, 0.1, 0.2);
  ASSERT_TRUE(normals[10]);
  EXPECT_NEAR(std::abs(normals[10]->x()), 1.0, 1e-9);
  std::vector<Eigen::Vector2d> scattered = {{0, 0}, {0.05, 0.05}, {0.0, 0.07}, {0.06, 0.0}};
  EXPECT_FALSE(scan_normals(scattered, 0.1, 0.2)[0]);
}

}  // namespace
}  // namespace traverse::frontend
