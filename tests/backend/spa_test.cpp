#include "spa.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "test_graphs.hpp"

namespace traverse::backend {
namespace {

// A square of four poses, two laps, measured without noise: the optimum has chi2 = 0.
PoseGraph exact_square() {
  std::vector<Pose2> truth;
  for (int k = 0; k < 8; ++k) truth.emplace_back(Pose2(0, 0, k * M_PI / 2) * Pose2(2.0, 0.0, 0.0));
  PoseGraph g;
  Eigen::Matrix3d info = Eigen::Vector3d(100.0, 25.0, 400.0).asDiagonal();
  for (int k = 0; k < 8; ++k) g.add_vertex(k, truth[k]);
  for (int k = 1; k < 8; ++k) g.edges.push_back({k - 1, k, between(truth[k - 1], truth[k]), info});
  for (int k = 0; k < 4; ++k) g.edges.push_back({k, k + 4, between(truth[k], truth[k + 4]), info});
  return g;
}

TEST(Spa, RecoversExactGraphFromPerturbedStart) {
  PoseGraph g = exact_square();
  const std::vector<Pose2> truth = g.poses;
  for (std::size_t k = 1; k < g.poses.size(); ++k) {
    g.poses[k] = g.poses[k] * Pose2(0.3, -0.2, 0.25);
  }
  SpaOptimizer optimizer;
  const SpaResult r = optimizer.optimize(g);
  EXPECT_TRUE(r.converged) << r.termination;
  EXPECT_GT(r.initial_chi2, 1.0);
  EXPECT_LT(r.final_chi2, 1e-12);
  EXPECT_TRUE(g.fixed[0]);
  for (std::size_t k = 0; k < g.poses.size(); ++k) {
    EXPECT_NEAR(g.poses[k].x(), truth[k].x(), 1e-7);
    EXPECT_NEAR(g.poses[k].y(), truth[k].y(), 1e-7);
    EXPECT_NEAR(wrap_angle(g.poses[k].theta() - truth[k].theta()), 0.0, 1e-7);
  }
}

TEST(Spa, ConvergesOnNoisyGraphToAStationaryPoint) {
  PoseGraph g = testing::make_walk_graph(150, 3);
  ASSERT_GT(g.edges.size(), 160u);  // loop closures exist
  SpaOptimizer optimizer;
  const SpaResult r = optimizer.optimize(g);
  EXPECT_TRUE(r.converged) << r.termination;
  EXPECT_LT(r.final_chi2, r.initial_chi2);
  // A second run from the optimum cannot lower chi2 by more than the tolerance.
  const SpaResult again = optimizer.optimize(g);
  EXPECT_TRUE(again.converged);
  EXPECT_NEAR(again.final_chi2, r.final_chi2, 1e-8 * r.final_chi2);
  // chi2 of a well-modelled graph is about (3 edges - 3 (vertices - 1)) in expectation.
  const double dof = 3.0 * (g.edges.size() - (g.poses.size() - 1));
  EXPECT_LT(r.final_chi2, 3.0 * dof);
}

TEST(Spa, ReusesSymbolicAnalysisWhileThePatternIsUnchanged) {
  PoseGraph g = testing::make_walk_graph(60, 5);
  SpaOptimizer optimizer;
  optimizer.optimize(g);
  EXPECT_EQ(optimizer.system().analyses(), 1);
  g.poses[10] = g.poses[10] * Pose2(0.2, 0.1, 0.1);  // new values, same pattern
  const SpaResult r = optimizer.optimize(g);
  EXPECT_GT(r.iterations, 1);
  EXPECT_EQ(optimizer.system().analyses(), 1);
  // A repeated measurement between already linked vertices keeps the block pattern.
  g.edges.push_back(g.edges[3]);
  optimizer.optimize(g);
  EXPECT_EQ(optimizer.system().analyses(), 1);
  // A new loop closure changes it.
  g.edges.push_back({2, 50, between(g.poses[2], g.poses[50]), Eigen::Matrix3d::Identity()});
  optimizer.optimize(g);
  EXPECT_EQ(optimizer.system().analyses(), 2);
}

TEST(Spa, AGrowingChainKeepsTheOrderingAndALoopOrdersAfresh) {
  PoseGraph g = testing::make_walk_graph(60, 0);
  SpaOptimizer optimizer;
  optimizer.optimize(g);
  EXPECT_EQ(optimizer.system().orderings_reused(), 0);
  // Key poses appended one by one, each linked to the newest: the ordering is extended.
  for (int k = 0; k < 10; ++k) {
    const int n = static_cast<int>(g.poses.size());
    const Pose2 step(0.5, 0.0, 0.05);
    g.add_vertex(n, g.poses.back() * step);
    g.edges.push_back({n - 1, n, step, Eigen::Matrix3d::Identity() * 100.0});
    const SpaResult r = optimizer.optimize(g);
    EXPECT_TRUE(r.converged);
  }
  EXPECT_EQ(optimizer.system().analyses(), 11);
  EXPECT_EQ(optimizer.system().orderings_reused(), 10);
  // A new vertex closing a loop to an old one is ordered afresh, and the answer is the same as
  // a fresh optimiser's.
  const int n = static_cast<int>(g.poses.size());
  g.add_vertex(n, g.poses.back() * Pose2(0.5, 0.0, 0.0));
  g.edges.push_back({n - 1, n, Pose2(0.5, 0.0, 0.0), Eigen::Matrix3d::Identity() * 100.0});
  g.edges.push_back({3, n, between(g.poses[3], g.poses[n]) * Pose2(0.05, 0.0, 0.0),
                     Eigen::Matrix3d::Identity() * 100.0});
  PoseGraph h = g;
  optimizer.optimize(g);
  EXPECT_EQ(optimizer.system().orderings_reused(), 10);
  SpaOptimizer fresh;
  fresh.optimize(h);
  for (int i = 0; i <= n; ++i) {
    EXPECT_NEAR((g.poses[i].translation() - h.poses[i].translation()).norm(), 0.0, 1e-9) << i;
  }
}

TEST(Spa, NonFiniteCostKeepsThePreviousState) {
  // A degenerate measurement (NaN information, as a failed matcher might produce) added to an
  // optimised graph: the optimiser reports it and leaves the poses untouched.
  PoseGraph g = testing::make_walk_graph(40, 9);
  SpaOptimizer optimizer;
  ASSERT_TRUE(optimizer.optimize(g).converged);
  const std::vector<Pose2> good = g.poses;
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(1, 1) = std::numeric_limits<double>::quiet_NaN();
  g.edges.push_back({0, 30, Pose2(1.0, 0.0, 0.0), bad});
  const SpaResult r = optimizer.optimize(g);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.termination.find("not positive definite"), std::string::npos) << r.termination;
  for (std::size_t k = 0; k < g.poses.size(); ++k) {
    EXPECT_EQ(g.poses[k].x(), good[k].x());
    EXPECT_EQ(g.poses[k].theta(), good[k].theta());
  }
}

TEST(Spa, RefusesAnInformationMatrixThatIsNotPositiveDefinite) {
  // Before: converged: true with chi2 4e11 and poses 45 km away.
  PoseGraph g = testing::make_walk_graph(30, 4);
  const std::vector<Pose2> start = g.poses;
  g.edges[5].information(0, 0) = -1000.0;
  const SpaResult r = SpaOptimizer().optimize(g);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.termination.find("edge 5 (5 -> 6)"), std::string::npos) << r.termination;
  EXPECT_EQ(g.poses[10].x(), start[10].x());
}

TEST(Spa, SolvesEachComponentOfADisconnectedGraph) {
  // Two copies of a walk side by side, sharing no edge: each keeps its first vertex fixed.
  PoseGraph a = testing::make_walk_graph(30, 5);
  PoseGraph g = a;
  const int n = static_cast<int>(a.poses.size());
  for (int k = 0; k < n; ++k) g.add_vertex(1000 + k, a.poses[k] * Pose2(0, 50, 0));
  for (Edge e : a.edges) {
    e.from += n;
    e.to += n;
    g.edges.push_back(e);
  }
  SpaOptimizer optimizer;
  const SpaResult r = optimizer.optimize(g);
  EXPECT_TRUE(r.converged) << r.termination;
  EXPECT_TRUE(g.fixed[0] && g.fixed[n]);
  const auto cov = optimizer.marginals(g);
  ASSERT_TRUE(cov);
  for (int k = 0; k < 2 * n; ++k) {
    EXPECT_LT((*cov)[k].trace(), 1.0) << k;  // metres and radians, not 4.7e28 m^2
  }
  EXPECT_NEAR((*cov)[5].trace(), (*cov)[n + 5].trace(), 1e-9);
}

TEST(Spa, HitsTheIterationCapWithoutClaimingConvergence) {
  PoseGraph g = testing::make_walk_graph(80, 4, 0.2);
  SpaConfig config;
  config.max_iterations = 1;
  SpaOptimizer optimizer(config);
  const SpaResult r = optimizer.optimize(g);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.termination, "iteration cap reached");
}

}  // namespace
}  // namespace traverse::backend
