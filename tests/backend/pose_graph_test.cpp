#include "pose_graph.hpp"

#include <gtest/gtest.h>

#include <random>

namespace traverse::backend {
namespace {

Eigen::Vector3d reference_error(const Pose2& xi, const Pose2& xj, const Pose2& z) {
  const Pose2 e = z.inverse() * (xi.inverse() * xj);
  return {e.x(), e.y(), wrap_angle(e.theta())};
}

TEST(EdgeError, IsTheErrorOfZInverseTimesRelativePose) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-4.0, 4.0), a(-M_PI, M_PI);
  for (int k = 0; k < 200; ++k) {
    const Pose2 xi(u(rng), u(rng), a(rng)), xj(u(rng), u(rng), a(rng)), z(u(rng), u(rng), a(rng));
    EXPECT_LT((edge_error(xi, xj, z) - reference_error(xi, xj, z)).norm(), 1e-12);
  }
}

TEST(EdgeError, ZeroWhenConsistentAndAngleWrapped) {
  const Pose2 xi(1.0, 2.0, 3.0), xj(-2.0, 0.5, -3.0);
  EXPECT_LT(edge_error(xi, xj, between(xi, xj)).norm(), 1e-12);
  // An angle difference of -6.2 rad wraps to 2 pi - 6.2 rad.
  const Eigen::Vector3d e = edge_error(Pose2(0, 0, 3.1), Pose2(0, 0, -3.1), Pose2());
  EXPECT_NEAR(e.z(), 2 * M_PI - 6.2, 1e-12);
}

TEST(EdgeError, TranslationIsInTheMeasurementFrame) {
  // Xi = identity, Xj = (1, 0, pi/2), Z = (0, 0, pi/2): Z^-1 Xj has translation (0, -1), so with
  // Omega = diag(1, 100, 1) chi2 is 100 (a world-frame residual would give 1).
  PoseGraph g;
  g.add_vertex(0, Pose2());
  g.add_vertex(1, Pose2(1.0, 0.0, M_PI / 2));
  Eigen::Matrix3d info = Eigen::Vector3d(1.0, 100.0, 1.0).asDiagonal();
  g.edges.push_back({0, 1, Pose2(0.0, 0.0, M_PI / 2), info});
  const Eigen::Vector3d e = edge_error(g.poses[0], g.poses[1], g.edges[0].T_from_to);
  EXPECT_NEAR(e.x(), 0.0, 1e-12);
  EXPECT_NEAR(e.y(), -1.0, 1e-12);
  EXPECT_NEAR(chi2(g), 100.0, 1e-9);
}

// Central differences on (x, y, theta) of each end, away from the +-pi wrap of the error angle.
void check_jacobians(const Pose2& xi, const Pose2& xj, const Pose2& z) {
  Eigen::Matrix3d J_i, J_j;
  edge_jacobians(xi, xj, z, J_i, J_j);
  const double h = 1e-6;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[c] = h;
    auto plus = [](const Pose2& p, const Eigen::Vector3d& v) {
      return Pose2(p.x() + v.x(), p.y() + v.y(), p.theta() + v.z());
    };
    const Eigen::Vector3d num_i =
        (edge_error(plus(xi, d), xj, z) - edge_error(plus(xi, -d), xj, z)) / (2 * h);
    const Eigen::Vector3d num_j =
        (edge_error(xi, plus(xj, d), z) - edge_error(xi, plus(xj, -d), z)) / (2 * h);
    EXPECT_LT((J_i.col(c) - num_i).norm(), 1e-6 * (1.0 + num_i.norm())) << "column " << c;
    EXPECT_LT((J_j.col(c) - num_j).norm(), 1e-6 * (1.0 + num_j.norm())) << "column " << c;
  }
}

TEST(EdgeJacobians, MatchNumericalDerivatives) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-10.0, 10.0), a(-M_PI, M_PI), small(-0.5, 0.5);
  for (int k = 0; k < 200; ++k) {
    const Pose2 xi(u(rng), u(rng), a(rng)), z(u(rng), u(rng), a(rng));
    // Xj near Xi Z so the error angle stays away from the wrap at +-pi.
    const Pose2 xj = xi * z * Pose2(small(rng), small(rng), small(rng));
    check_jacobians(xi, xj, z);
  }
}

TEST(EdgeJacobians, MatchNearZeroAndNearPiHeadings) {
  check_jacobians(Pose2(0, 0, 1e-12), Pose2(1e-9, -1e-9, -1e-12), Pose2());
  check_jacobians(Pose2(1, 2, M_PI - 1e-9), Pose2(-3, 4, -M_PI + 1e-9), Pose2(0.5, 0.1, 2e-9));
  check_jacobians(Pose2(1, 2, 0.5), Pose2(1, 2, 0.5), Pose2(0, 0, 0));
}

TEST(PoseGraph, FixesFirstVertexOnlyWhenNoneFixed) {
  PoseGraph g;
  g.add_vertex(10, Pose2());
  g.add_vertex(11, Pose2(), true);
  g.edges.push_back({0, 1, Pose2(), Eigen::Matrix3d::Identity()});
  g.fix_gauge_if_free();
  EXPECT_FALSE(g.fixed[0]);
  g.fixed[1] = false;
  g.fix_gauge_if_free();
  EXPECT_TRUE(g.fixed[0]);
  EXPECT_EQ(g.index_of(11), 1);
  EXPECT_EQ(g.index_of(12), -1);
}

TEST(PoseGraph, FixesOneVertexPerComponent) {
  // Two chains that share no edge: a gauge for each, else H is singular (the free component's
  // marginals came out as 4.7e28 m^2).
  PoseGraph g;
  for (int k = 0; k < 5; ++k) g.add_vertex(k, Pose2(k, 0, 0));
  g.edges.push_back({0, 1, Pose2(1, 0, 0), Eigen::Matrix3d::Identity()});
  g.edges.push_back({3, 2, Pose2(-1, 0, 0), Eigen::Matrix3d::Identity()});
  g.edges.push_back({3, 4, Pose2(1, 0, 0), Eigen::Matrix3d::Identity()});
  int count = 0;
  EXPECT_EQ(components(g, &count), (std::vector<int>{0, 0, 1, 1, 1}));
  EXPECT_EQ(count, 2);
  g.fix_gauge_if_free();
  EXPECT_EQ(g.fixed, (std::vector<bool>{true, false, true, false, false}));
}

TEST(PoseGraph, InitialisesFromEdgesAlongASpanningTree) {
  PoseGraph g;
  for (int k = 0; k < 3; ++k) g.add_vertex(k, Pose2());
  g.edges.push_back({0, 1, Pose2(1, 0, M_PI / 2), Eigen::Matrix3d::Identity()});
  g.edges.push_back({2, 1, Pose2(0, -1, 0), Eigen::Matrix3d::Identity()});  // against the tree
  initialise_from_edges(g);
  EXPECT_NEAR(g.poses[1].x(), 1.0, 1e-12);
  EXPECT_NEAR(g.poses[1].theta(), M_PI / 2, 1e-12);
  // T_w2 = T_w1 (T_21)^-1: vertex 1 is 1 m to the right of vertex 2, so 2 is 1 m left of 1.
  EXPECT_NEAR(g.poses[2].x(), 1.0 - 1.0, 1e-12);
  EXPECT_NEAR(g.poses[2].y(), 0.0, 1e-12);
  EXPECT_NEAR(g.poses[2].theta(), M_PI / 2, 1e-12);
}

TEST(PoseGraph, PositiveDefiniteInformation) {
  EXPECT_TRUE(positive_definite(Eigen::Matrix3d::Identity()));
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  m(0, 0) = -1000;
  EXPECT_FALSE(positive_definite(m));
  m = Eigen::Matrix3d::Identity();
  m(2, 2) = 0;  // semi-definite: rotation unconstrained
  EXPECT_FALSE(positive_definite(m));
  m = Eigen::Matrix3d::Identity();
  m(0, 1) = 5;  // not symmetric
  EXPECT_FALSE(positive_definite(m));
}

}  // namespace
}  // namespace traverse::backend
