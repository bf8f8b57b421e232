#include "pose_graph.hpp"

#include <cmath>

namespace traverse::backend {

int PoseGraph::add_vertex(int64_t id, const Pose2& T_world_vertex, bool is_fixed) {
  poses.push_back(T_world_vertex);
  ids.push_back(id);
  fixed.push_back(is_fixed);
  return static_cast<int>(poses.size()) - 1;
}

int PoseGraph::index_of(int64_t id) const {
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == id) return static_cast<int>(i);
  }
  return -1;
}

void PoseGraph::fix_gauge_if_free() {
  if (poses.empty()) return;
  for (bool f : fixed) {
    if (f) return;
  }
  fixed[0] = true;
}

Eigen::Vector3d edge_error(const Pose2& T_world_i, const Pose2& T_world_j, const Pose2& Z) {
  // Z^-1 Xi^-1 Xj: translation R(theta_i + theta_z)^T (tj - ti) - R(theta_z)^T tz.
  const double a = T_world_i.theta() + Z.theta();
  const double c = std::cos(a), s = std::sin(a);
  const double cz = std::cos(Z.theta()), sz = std::sin(Z.theta());
  const double dx = T_world_j.x() - T_world_i.x(), dy = T_world_j.y() - T_world_i.y();
  return {c * dx + s * dy - (cz * Z.x() + sz * Z.y()),
          -s * dx + c * dy - (-sz * Z.x() + cz * Z.y()),
          wrap_angle(T_world_j.theta() - T_world_i.theta() - Z.theta())};
}

void edge_jacobians(const Pose2& T_world_i, const Pose2& T_world_j, const Pose2& Z,
                    Eigen::Matrix3d& J_i, Eigen::Matrix3d& J_j) {
  const double a = T_world_i.theta() + Z.theta();
  const double c = std::cos(a), s = std::sin(a);
  const double dx = T_world_j.x() - T_world_i.x(), dy = T_world_j.y() - T_world_i.y();
  // Translation part R(a)^T (tj - ti): d/dti = -R^T, d/dtj = R^T, d/dtheta_i = dR^T/da (tj - ti).
  J_j << c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0;
  J_i << -c, -s, -s * dx + c * dy, s, -c, -c * dx - s * dy, 0.0, 0.0, -1.0;
}

double chi2(const PoseGraph& graph, const std::vector<Pose2>& poses) {
  double sum = 0.0;
  for (const Edge& e : graph.edges) {
    const Eigen::Vector3d r = edge_error(poses[e.from], poses[e.to], e.T_from_to);
    sum += r.dot(e.information * r);
  }
  return sum;
}

double chi2(const PoseGraph& graph) { return chi2(graph, graph.poses); }

}  // namespace traverse::backend
