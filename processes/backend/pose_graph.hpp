// A 2D pose graph: vertices are poses T_world_vertex, edges are relative-pose measurements Z with a
// 3x3 information matrix Omega, as in Sparse Pose Adjustment (Konolige et al., "Efficient Sparse
// Pose Adjustment for 2D Mapping", IROS 2010).
//
// The error of an edge follows g2o's EDGE_SE2 so that chi2 figures compare with other tools:
//   e = t2v(Z^-1 (Xi^-1 Xj)),
// i.e. the translation of the residual transform expressed in the measurement's frame, and its
// angle wrapped to (-pi, pi]. chi2 = sum over edges of e^T Omega e. Poses are updated additively on
// (x [m], y [m], theta [rad]), so the Jacobians here are with respect to those three numbers.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "se2.hpp"

namespace traverse::backend {

struct Edge {
  int from = 0;  // index into PoseGraph::poses (not the file's vertex id)
  int to = 0;
  Pose2 T_from_to;  // measurement Z: pose of `to` in the frame of `from`
  Eigen::Matrix3d information =
      Eigen::Matrix3d::Identity();  // Omega, units 1/m^2, 1/(m rad), 1/rad^2
};

struct PoseGraph {
  std::vector<Pose2> poses;  // T_world_vertex per vertex
  std::vector<int64_t> ids;  // the vertex ids of the source file, parallel to poses
  std::vector<bool> fixed;   // gauge: fixed vertices are not optimised
  std::vector<Edge> edges;

  // Appends a vertex and returns its index.
  int add_vertex(int64_t id, const Pose2& T_world_vertex, bool is_fixed = false);
  // Index of a vertex id, or -1.
  int index_of(int64_t id) const;
  // Fixes the first vertex of every connected component that has no fixed vertex (the gauge of
  // SPA: a component left free makes H singular).
  void fix_gauge_if_free();
};

// The connected component of every vertex (0, 1, ... in order of their first vertex), through
// the edges in either direction; `count` is set to the number of components.
std::vector<int> components(const PoseGraph& graph, int* count = nullptr);

// Sets every vertex's pose by composing the edges along a spanning tree (breadth first from the
// first vertex of each component, which stays where it is): the initial guess for a graph given
// by its edges alone.
void initialise_from_edges(PoseGraph& graph);

// How far from symmetric an information matrix may be, relative to its norm: the rounding of an
// inverse (a held link's, 0.1 to 1e6, is off by 1e-6, which Eigen's isApprox would refuse).
inline constexpr double kSymmetryTolerance = 1e-9;

// A 3x3 information matrix as used: its symmetric part, when it is finite, symmetric up to
// kSymmetryTolerance and positive definite (its Cholesky exists); nullopt otherwise.
std::optional<Eigen::Matrix3d> usable_information(const Eigen::Matrix3d& information);

// True when usable_information(information) has a value.
bool positive_definite(const Eigen::Matrix3d& information);

// e = t2v(Z^-1 (Xi^-1 Xj)) of one edge, given the two vertex poses.
Eigen::Vector3d edge_error(const Pose2& T_world_i, const Pose2& T_world_j, const Pose2& Z);

// de/dXi and de/dXj of edge_error on the additive (x, y, theta) parameterisation.
void edge_jacobians(const Pose2& T_world_i, const Pose2& T_world_j, const Pose2& Z,
                    Eigen::Matrix3d& J_i, Eigen::Matrix3d& J_j);

// sum over edges of e^T Omega e (dimensionless).
double chi2(const PoseGraph& graph);
double chi2(const PoseGraph& graph, const std::vector<Pose2>& poses);

}  // namespace traverse::backend
