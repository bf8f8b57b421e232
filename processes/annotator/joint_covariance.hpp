// Joint covariances of key poses from the pose graph, for the local view of the annotator.
//
// The backend publishes only the marginal covariance of each key pose: its error relative to the
// first key pose, which fixes the frame. What a surveyor checks a wall against is the error of one
// key pose relative to its neighbours, and that needs the cross-covariance of the two:
// Cov(x_j - x_i) = Sigma_ii + Sigma_jj - Sigma_ij - Sigma_ji (with the rotation of i's frame, see
// relative_position_covariance). The annotator keeps a copy of the graph (KEY_POSES poses and
// POSE_GRAPH_EDGES edges), linearises it at the published poses and factors the information
// matrix H with the backend's own SPA/CHOLMOD code (spa.hpp: same H as the backend's marginals);
// the columns of H^-1 belonging to key pose i then come from one solve with three right-hand
// sides, Sigma(:, i) = H^-1 E_i (Kaess & Dellaert 2009 recover them the same way, from the square
// root factor). One solve costs about two passes over the factor, so the columns are computed
// only for the key poses whose annotation is being recomputed.
#pragma once

#include <cholmod.h>

#include <Eigen/Core>
#include <vector>

#include "pose_graph.hpp"
#include "se2.hpp"
#include "spa.hpp"

namespace traverse::annotator {

class JointCovariance {
 public:
  JointCovariance();
  ~JointCovariance();
  JointCovariance(const JointCovariance&) = delete;
  JointCovariance& operator=(const JointCovariance&) = delete;

  // Linearises `graph` at its poses (vertex 0 must be its only fixed vertex) and factors H. False
  // when H is singular or the graph falls into pieces.
  bool factor(backend::PoseGraph& graph);
  // Marginal covariance of vertex v [m^2, m rad, rad^2] (zero for the fixed vertex 0).
  const Eigen::Matrix3d& marginal(int v) const { return marginals_[v]; }
  // Computes the three columns of H^-1 that belong to vertex v; false if the solve failed.
  bool compute_column(int v);
  // E[dx_w dx_v^T] from the last compute_column(v) (zero if either is vertex 0).
  Eigen::Matrix3d cross(int w) const;
  int vertices() const { return static_cast<int>(marginals_.size()); }

 private:
  backend::SpaOptimizer spa_;
  cholmod_common common_;
  std::vector<Eigen::Matrix3d> marginals_;
  Eigen::MatrixXd column_;  // 3 (n - 1) x 3
  int column_vertex_ = -1;
};

// Covariance [m^2] of the position of key pose j in the frame of key pose i, R_i^T (t_j - t_i),
// from the joint covariance of both on (x, y, theta): S_ii, S_jj and S_ij = E[dx_i dx_j^T]. To
// first order its error is R_i^T (dt_j - dt_i - J (t_j - t_i) dtheta_i), J the 90 degree rotation:
// a heading error of i swings j about i. Does not depend on which vertex fixes the frame.
Eigen::Matrix2d relative_position_covariance(const Pose2& T_world_i, const Pose2& T_world_j,
                                             const Eigen::Matrix3d& S_ii,
                                             const Eigen::Matrix3d& S_jj,
                                             const Eigen::Matrix3d& S_ij);

}  // namespace traverse::annotator
