#include "marginals.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "spa.hpp"
#include "test_graphs.hpp"

namespace traverse::backend {
namespace {

// The information matrix H = sum J^T Omega J over the free vertices (all but vertex 0), dense.
Eigen::MatrixXd dense_information(const PoseGraph& g) {
  const int n = static_cast<int>(g.poses.size()) - 1;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (const Edge& e : g.edges) {
    Eigen::Matrix3d J[2];
    edge_jacobians(g.poses[e.from], g.poses[e.to], e.T_from_to, J[0], J[1]);
    const int v[2] = {e.from - 1, e.to - 1};
    for (int a = 0; a < 2; ++a) {
      for (int b = 0; b < 2; ++b) {
        if (v[a] < 0 || v[b] < 0) continue;
        H.block<3, 3>(3 * v[a], 3 * v[b]) += J[a].transpose() * e.information * J[b];
      }
    }
  }
  return H;
}

void expect_blocks_equal_dense_inverse(const PoseGraph& g,
                                       const std::vector<Eigen::Matrix3d>& blocks) {
  const Eigen::MatrixXd sigma = dense_information(g).inverse();
  ASSERT_EQ(blocks.size(), g.poses.size());
  EXPECT_EQ(blocks[0], Eigen::Matrix3d::Zero());  // the fixed gauge vertex
  for (std::size_t v = 1; v < g.poses.size(); ++v) {
    const Eigen::Matrix3d expected = sigma.block<3, 3>(3 * (v - 1), 3 * (v - 1));
    EXPECT_LE((blocks[v] - expected).norm(), 1e-9 * expected.norm()) << "vertex " << v;
  }
}

TEST(Marginals, EqualTheDenseInverseOnASmallGraph) {
  PoseGraph g = testing::make_walk_graph(180, 21);
  SpaOptimizer optimizer;
  ASSERT_TRUE(optimizer.optimize(g).converged);
  const auto blocks = optimizer.marginals(g);
  ASSERT_TRUE(blocks);
  expect_blocks_equal_dense_inverse(g, *blocks);
}

// The recursion must not depend on how CHOLMOD stores the factor.
class MarginalsFactorKinds : public ::testing::TestWithParam<std::tuple<Ordering, int>> {};

TEST_P(MarginalsFactorKinds, EqualTheDenseInverse) {
  const auto [ordering, supernodal] = GetParam();
  PoseGraph g = testing::make_walk_graph(120, 8);
  SpaOptimizer(SpaConfig{}).optimize(g);
  BlockCholesky system(ordering, supernodal);
  std::vector<std::pair<int, int>> pairs;
  for (const Edge& e : g.edges) {
    if (e.from > 0 && e.to > 0) pairs.emplace_back(e.from - 1, e.to - 1);
  }
  const std::vector<int> handles = system.set_pattern(static_cast<int>(g.poses.size()) - 1, pairs);
  const Eigen::MatrixXd H = dense_information(g);
  for (int j = 0; j < system.num_blocks(); ++j) system.add_diagonal(j, H.block<3, 3>(3 * j, 3 * j));
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [a, b] = pairs[k];
    // Repeated pairs accumulate, so add each distinct block once: the first handle of a pair.
    bool first = true;
    for (std::size_t q = 0; q < k; ++q) {
      if (pairs[q] == pairs[k] || pairs[q] == std::make_pair(b, a)) first = false;
    }
    if (first) system.add_off_diagonal(handles[k], H.block<3, 3>(3 * a, 3 * b));
  }
  ASSERT_TRUE(system.factorize(0.0));
  EXPECT_EQ(system.factor()->is_super, supernodal == CHOLMOD_SUPERNODAL);
  const auto blocks = diagonal_blocks_of_inverse(system.factor(), system.common());
  ASSERT_TRUE(blocks);
  std::vector<Eigen::Matrix3d> with_gauge{Eigen::Matrix3d::Zero()};
  with_gauge.insert(with_gauge.end(), blocks->begin(), blocks->end());
  expect_blocks_equal_dense_inverse(g, with_gauge);
}

INSTANTIATE_TEST_SUITE_P(
    OrderingsAndStorage, MarginalsFactorKinds,
    ::testing::Combine(::testing::Values(Ordering::kScalarDefault, Ordering::kBlockAmd,
                                         Ordering::kBlockMetis),
                       ::testing::Values(CHOLMOD_SIMPLICIAL, CHOLMOD_SUPERNODAL)));

TEST(Marginals, OdometryChainVarianceGrowsLinearlyInSquareMetres) {
  // A straight chain along x with sigma_x = 0.1 m per step: var(x_k) = k * 0.01 m^2 exactly,
  // because along a straight chain x is decoupled from heading and y (to first order).
  PoseGraph g;
  const Eigen::Matrix3d info = Eigen::Vector3d(1.0 / 0.01, 1.0 / 0.0004, 1.0 / 1e-4).asDiagonal();
  g.add_vertex(0, Pose2());
  for (int k = 1; k <= 20; ++k) {
    g.add_vertex(k, Pose2(k, 0.0, 0.0));
    g.edges.push_back({k - 1, k, Pose2(1.0, 0.0, 0.0), info});
  }
  SpaOptimizer optimizer;
  const auto cov = optimizer.marginals(g);
  ASSERT_TRUE(cov);
  for (int k = 1; k <= 20; ++k) {
    EXPECT_NEAR((*cov)[k](0, 0), 0.01 * k, 1e-12) << k;
    EXPECT_NEAR((*cov)[k](2, 2), 1e-4 * k, 1e-14) << k;
    // Lateral: each step's own 0.0004 m^2 plus its heading error (1e-4 rad^2) times the lever arm
    // to pose k squared: k * 0.0004 + 1e-4 * sum_{j<k} j^2 [m^2].
    const double lever = (k - 1.0) * k * (2.0 * k - 1.0) / 6.0;
    EXPECT_NEAR((*cov)[k](1, 1), 0.0004 * k + 1e-4 * lever, 1e-12) << k;
  }
}

TEST(Marginals, SingularInformationIsReported) {
  PoseGraph g;  // the only edge says nothing about the heading of vertex 1
  g.add_vertex(0, Pose2());
  g.add_vertex(1, Pose2(1.0, 0.0, 0.0));
  Eigen::Matrix3d no_heading = Eigen::Matrix3d::Identity();
  no_heading(2, 2) = 0.0;
  g.edges.push_back({0, 1, Pose2(1.0, 0.0, 0.0), no_heading});
  SpaOptimizer optimizer;
  EXPECT_FALSE(optimizer.marginals(g));
}

TEST(Marginals, AVertexWithoutEdgesIsItsOwnFixedComponent) {
  PoseGraph g;
  g.add_vertex(0, Pose2());
  g.add_vertex(1, Pose2(1.0, 0.0, 0.0));
  g.add_vertex(2, Pose2(2.0, 0.0, 0.0));
  g.edges.push_back({0, 1, Pose2(1.0, 0.0, 0.0), Eigen::Matrix3d::Identity()});
  SpaOptimizer optimizer;
  const auto cov = optimizer.marginals(g);
  ASSERT_TRUE(cov);
  EXPECT_EQ((*cov)[2], Eigen::Matrix3d::Zero());
  EXPECT_GT((*cov)[1](0, 0), 0.0);
}

}  // namespace
}  // namespace traverse::backend
