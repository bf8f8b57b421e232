#include "joint_covariance.hpp"

#include <algorithm>

namespace traverse::annotator {

JointCovariance::JointCovariance() { cholmod_start(&common_); }

JointCovariance::~JointCovariance() { cholmod_finish(&common_); }

bool JointCovariance::factor(backend::PoseGraph& graph) {
  column_vertex_ = -1;
  marginals_.clear();
  // SpaOptimizer::marginals linearises the graph, factors H (vertex 0 fixed) and recovers the
  // diagonal blocks of H^-1; its factor stays in spa_.system() for the column solves below.
  auto marginals = spa_.marginals(graph);
  // SPA fixes one vertex per connected component: a graph in pieces has no joint covariance
  // between them (and its blocks would not be numbered v - 1 any more).
  if (!marginals || std::count(graph.fixed.begin(), graph.fixed.end(), true) != 1) return false;
  marginals_ = std::move(*marginals);
  return true;
}

bool JointCovariance::compute_column(int v) {
  column_vertex_ = -1;
  const cholmod_factor* L = spa_.system().factor();
  const int n = static_cast<int>(marginals_.size());
  if (!L || v < 0 || v >= n) return false;
  column_.setZero(3 * (n - 1), 3);
  if (v > 0) {
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(3 * (n - 1), 3);
    rhs.block<3, 3>(3 * (v - 1), 0).setIdentity();
    cholmod_dense b{};
    b.nrow = b.d = rhs.rows();
    b.ncol = 3;
    b.nzmax = rhs.size();
    b.x = rhs.data();
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    // cholmod_solve reads the factor only; it takes a non-const pointer for other modes.
    cholmod_dense* x = cholmod_solve(CHOLMOD_A, const_cast<cholmod_factor*>(L), &b, &common_);
    if (!x) return false;
    column_ = Eigen::Map<const Eigen::MatrixXd>(static_cast<double*>(x->x), rhs.rows(), 3);
    cholmod_free_dense(&x, &common_);
    if (!column_.allFinite()) return false;
  }
  column_vertex_ = v;
  return true;
}

Eigen::Matrix3d JointCovariance::cross(int w) const {
  if (column_vertex_ < 0 || w <= 0) return Eigen::Matrix3d::Zero();
  return column_.block<3, 3>(3 * (w - 1), 0);
}

Eigen::Matrix2d relative_position_covariance(const Pose2& T_world_i, const Pose2& T_world_j,
                                             const Eigen::Matrix3d& S_ii,
                                             const Eigen::Matrix3d& S_jj,
                                             const Eigen::Matrix3d& S_ij) {
  const Eigen::Vector2d d = T_world_j.translation() - T_world_i.translation();
  Eigen::Matrix<double, 2, 3> A_i, A_j;
  A_i << -1.0, 0.0, d.y(), 0.0, -1.0, -d.x();  // -[I, J d], J d = (-d_y, d_x)
  A_j << 1.0, 0.0, 0.0, 0.0, 1.0, 0.0;
  const Eigen::Matrix2d cross = A_i * S_ij * A_j.transpose();
  const Eigen::Matrix2d world =
      A_i * S_ii * A_i.transpose() + A_j * S_jj * A_j.transpose() + cross + cross.transpose();
  const Eigen::Matrix2d R = T_world_i.rotation();
  return R.transpose() * world * R;
}

}  // namespace traverse::annotator
