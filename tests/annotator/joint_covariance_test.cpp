// Joint covariance columns against the dense inverse of the same information matrix, and the
// relative position covariance against numerical differentiation.
#include "joint_covariance.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace traverse::annotator {
namespace {

// A square of 8 poses with a loop closure from the last back to the first, uneven information.
backend::PoseGraph square() {
  backend::PoseGraph g;
  const Pose2 step(1.0, 0.0, M_PI / 4.0);
  Pose2 T;
  for (int i = 0; i < 8; ++i) {
    g.add_vertex(i, Pose2(T.x() + 0.01 * i, T.y() - 0.02 * (i % 3), T.theta()), i == 0);
    T = T * step;
  }
  auto add = [&](int from, int to, const Pose2& Z, double s_xy, double s_th) {
    backend::Edge e;
    e.from = from;
    e.to = to;
    e.T_from_to = Z;
    e.information =
        Eigen::Vector3d(1 / (s_xy * s_xy), 0.5 / (s_xy * s_xy), 1 / (s_th * s_th)).asDiagonal();
    e.information(0, 1) = e.information(1, 0) = 0.2 / (s_xy * s_xy);
    g.edges.push_back(e);
  };
  for (int i = 0; i + 1 < 8; ++i) add(i, i + 1, step, 0.01 * (1 + i % 2), 0.002);
  add(7, 0, step, 0.02, 0.004);
  return g;
}

// H of the free vertices (1..n-1) assembled densely from the same Jacobians.
Eigen::MatrixXd dense_information(const backend::PoseGraph& g) {
  const int n = static_cast<int>(g.poses.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3 * (n - 1), 3 * (n - 1));
  for (const backend::Edge& e : g.edges) {
    Eigen::Matrix3d Ji, Jj;
    backend::edge_jacobians(g.poses[e.from], g.poses[e.to], e.T_from_to, Ji, Jj);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, 3 * (n - 1));
    if (e.from > 0) J.block<3, 3>(0, 3 * (e.from - 1)) = Ji;
    if (e.to > 0) J.block<3, 3>(0, 3 * (e.to - 1)) = Jj;
    H += J.transpose() * e.information * J;
  }
  return H;
}

TEST(JointCovariance, ColumnsAndMarginalsEqualTheDenseInverse) {
  backend::PoseGraph g = square();
  const Eigen::MatrixXd S = dense_information(g).inverse();
  JointCovariance joint;
  ASSERT_TRUE(joint.factor(g));
  ASSERT_EQ(joint.vertices(), 8);
  EXPECT_TRUE(joint.marginal(0).isZero());
  for (int v = 1; v < 8; ++v) {
    EXPECT_TRUE(joint.marginal(v).isApprox(S.block<3, 3>(3 * (v - 1), 3 * (v - 1)), 1e-9)) << v;
  }
  ASSERT_TRUE(joint.compute_column(3));
  for (int w = 1; w < 8; ++w) {
    EXPECT_TRUE(joint.cross(w).isApprox(S.block<3, 3>(3 * (w - 1), 3 * 2), 1e-9)) << w;
  }
  EXPECT_TRUE(joint.cross(0).isZero());
}

TEST(JointCovariance, GraphInPiecesIsRefused) {
  backend::PoseGraph g = square();
  g.add_vertex(8, Pose2(5, 5, 0));  // no edge reaches it: nothing relates it to the others
  JointCovariance joint;
  EXPECT_FALSE(joint.factor(g));
}

TEST(RelativePositionCovariance, MatchesNumericalJacobian) {
  const Pose2 Ti(1.0, 2.0, 0.7), Tj(3.5, 1.0, -0.4);
  // f(x_i, x_j) = R_i^T (t_j - t_i): differentiate numerically on (x, y, theta) of both.
  auto f = [](const Eigen::Matrix<double, 6, 1>& x) {
    const Pose2 a(x[0], x[1], x[2]), b(x[3], x[4], x[5]);
    return Eigen::Vector2d(a.rotation().transpose() * (b.translation() - a.translation()));
  };
  Eigen::Matrix<double, 6, 1> x0;
  x0 << Ti.vector(), Tj.vector();
  Eigen::Matrix<double, 2, 6> A;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d[k] = 1e-6;
    A.col(k) = (f(x0 + d) - f(x0 - d)) / 2e-6;
  }
  Eigen::Matrix<double, 6, 6> M = Eigen::Matrix<double, 6, 6>::Random();
  const Eigen::Matrix<double, 6, 6> S = 1e-4 * M * M.transpose();
  const Eigen::Matrix2d expected = A * S * A.transpose();
  const Eigen::Matrix2d got = relative_position_covariance(
      Ti, Tj, S.block<3, 3>(0, 0), S.block<3, 3>(3, 3), S.block<3, 3>(0, 3));
  EXPECT_TRUE(got.isApprox(expected, 1e-6)) << got << "\n" << expected;
}

TEST(RelativePositionCovariance, RigidlyCorrelatedPosesHaveNone) {
  // Both poses moved by the same rigid motion (one shared error): nothing relative is uncertain.
  const Pose2 Ti(1.0, 2.0, 0.3), Tj(4.0, 0.0, 1.1);
  // The additive (x, y, theta) change of a pose under a small world motion (dx, dy, dth):
  // d t = (dx, dy) + J t dth, d theta = dth.
  auto G = [](const Pose2& T) {
    Eigen::Matrix3d g = Eigen::Matrix3d::Identity();
    g(0, 2) = -T.y();
    g(1, 2) = T.x();
    return g;
  };
  const Eigen::Matrix3d W = Eigen::Vector3d(0.01, 0.02, 0.003).asDiagonal();
  const Eigen::Matrix2d c =
      relative_position_covariance(Ti, Tj, G(Ti) * W * G(Ti).transpose(),
                                   G(Tj) * W * G(Tj).transpose(), G(Ti) * W * G(Tj).transpose());
  EXPECT_LT(c.norm(), 1e-12);
}

}  // namespace
}  // namespace traverse::annotator
