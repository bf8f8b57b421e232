#include "pose_graph.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <queue>

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
  int count = 0;
  const std::vector<int> component = components(*this, &count);
  std::vector<bool> has_fixed(count, false);
  for (std::size_t v = 0; v < poses.size(); ++v) {
    if (fixed[v]) has_fixed[component[v]] = true;
  }
  for (std::size_t v = 0; v < poses.size(); ++v) {
    if (!has_fixed[component[v]]) {
      fixed[v] = true;
      has_fixed[component[v]] = true;
    }
  }
}

namespace {

// For every vertex, the edges that touch it (edge indices).
std::vector<std::vector<int>> incident_edges(const PoseGraph& graph) {
  std::vector<std::vector<int>> incident(graph.poses.size());
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    incident[graph.edges[k].from].push_back(static_cast<int>(k));
    incident[graph.edges[k].to].push_back(static_cast<int>(k));
  }
  return incident;
}

// Breadth-first search from every unvisited vertex in index order; visit(edge, from, to) for each
// tree edge, `from` already reached.
template <class Visit>
std::vector<int> spanning_forest(const PoseGraph& graph, int* count, Visit visit) {
  const auto incident = incident_edges(graph);
  std::vector<int> component(graph.poses.size(), -1);
  int next = 0;
  for (std::size_t root = 0; root < graph.poses.size(); ++root) {
    if (component[root] >= 0) continue;
    std::queue<int> open;
    open.push(static_cast<int>(root));
    component[root] = next;
    while (!open.empty()) {
      const int v = open.front();
      open.pop();
      for (int k : incident[v]) {
        const Edge& e = graph.edges[k];
        const int w = e.from == v ? e.to : e.from;
        if (component[w] >= 0) continue;
        component[w] = next;
        visit(e, v, w);
        open.push(w);
      }
    }
    ++next;
  }
  if (count) *count = next;
  return component;
}

}  // namespace

std::vector<int> components(const PoseGraph& graph, int* count) {
  return spanning_forest(graph, count, [](const Edge&, int, int) {});
}

void initialise_from_edges(PoseGraph& graph) {
  spanning_forest(graph, nullptr, [&graph](const Edge& e, int from, int to) {
    // T_world_to = T_world_from Z along the edge, or T_world_from Z^-1 against it.
    graph.poses[to] = e.from == from ? graph.poses[from] * e.T_from_to
                                     : graph.poses[from] * e.T_from_to.inverse();
  });
}

std::optional<Eigen::Matrix3d> usable_information(const Eigen::Matrix3d& information) {
  if (!information.allFinite()) return std::nullopt;
  const Eigen::Matrix3d symmetric = 0.5 * (information + information.transpose());
  if ((information - information.transpose()).norm() > kSymmetryTolerance * symmetric.norm()) {
    return std::nullopt;
  }
  if (Eigen::LLT<Eigen::Matrix3d>(symmetric).info() != Eigen::Success) return std::nullopt;
  return symmetric;
}

bool positive_definite(const Eigen::Matrix3d& information) {
  return usable_information(information).has_value();
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
