#include "graph_io.hpp"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <unordered_map>
#include <vector>

namespace traverse::backend {
namespace {

struct PendingEdge {
  int64_t from, to;
  Edge edge;
  std::size_t line;
};

// Reads exactly n numbers from the rest of the line; false if fewer, unparsable, or extra tokens.
bool read_numbers(std::istringstream& in, double* out, int n) {
  for (int k = 0; k < n; ++k) {
    if (!(in >> out[k])) return false;
  }
  std::string extra;
  return !(in >> extra);
}

Eigen::Matrix3d symmetric(double i11, double i12, double i13, double i22, double i23, double i33) {
  Eigen::Matrix3d m;
  m << i11, i12, i13, i12, i22, i23, i13, i23, i33;
  return m;
}

}  // namespace

GraphReadResult read_pose_graph(std::istream& in, const std::string& name) {
  GraphReadResult result;
  PoseGraph graph;
  std::unordered_map<int64_t, int> index;
  std::vector<PendingEdge> pending;
  std::vector<int64_t> fixed_ids;
  auto fail = [&](std::size_t line, const std::string& what) {
    result.error = name + ":" + std::to_string(line) + ": " + what;
    return result;
  };

  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::istringstream ls(text);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "VERTEX_SE2" || tag == "VERTEX2") {
      int64_t id;
      double v[3];
      if (!(ls >> id) || !read_numbers(ls, v, 3)) {
        return fail(line, tag + " needs: id x y theta");
      }
      if (!index.emplace(id, static_cast<int>(graph.poses.size())).second) {
        return fail(line, "vertex " + std::to_string(id) + " defined twice");
      }
      graph.add_vertex(id, Pose2(v[0], v[1], v[2]));
    } else if (tag == "EDGE_SE2" || tag == "EDGE2") {
      PendingEdge p{};
      double v[9];
      if (!(ls >> p.from >> p.to) || !read_numbers(ls, v, 9)) {
        return fail(line, tag + " needs: i j dx dy dtheta and 6 information entries");
      }
      p.edge.T_from_to = Pose2(v[0], v[1], v[2]);
      // g2o: I11 I12 I13 I22 I23 I33; TORO: I11 I12 I22 I33 I13 I23.
      p.edge.information = tag == "EDGE_SE2" ? symmetric(v[3], v[4], v[5], v[6], v[7], v[8])
                                             : symmetric(v[3], v[4], v[7], v[5], v[8], v[6]);
      if (!p.edge.information.allFinite()) return fail(line, "information is not finite");
      if (!positive_definite(p.edge.information)) {
        return fail(line, "information matrix of edge " + std::to_string(p.from) + " -> " +
                              std::to_string(p.to) + " is not positive definite");
      }
      p.line = line;
      pending.push_back(p);
    } else if (tag == "FIX") {
      int64_t id;
      while (ls >> id) fixed_ids.push_back(id);
      if (!ls.eof()) return fail(line, "FIX needs vertex ids");
    } else {
      return fail(line, "unsupported record '" + tag +
                            "' (expected VERTEX_SE2, EDGE_SE2, FIX, "
                            "VERTEX2 or EDGE2)");
    }
  }
  if (graph.poses.empty() && pending.empty()) {
    result.error = name + ": no vertices and no edges (an empty file?)";
    return result;
  }
  // Edges alone: a vertex per id named, in id order, placed later along a spanning tree.
  const bool from_edges = graph.poses.empty();
  if (from_edges) {
    std::map<int64_t, bool> ids;
    for (const PendingEdge& p : pending) ids[p.from] = ids[p.to] = true;
    for (const auto& [id, unused] : ids) {
      index.emplace(id, static_cast<int>(graph.poses.size()));
      graph.add_vertex(id, Pose2());
    }
  }
  for (PendingEdge& p : pending) {
    const auto a = index.find(p.from), b = index.find(p.to);
    if (a == index.end() || b == index.end()) {
      return fail(p.line, "edge names undefined vertex " +
                              std::to_string(a == index.end() ? p.from : p.to));
    }
    if (a->second == b->second) return fail(p.line, "edge connects a vertex to itself");
    p.edge.from = a->second;
    p.edge.to = b->second;
    graph.edges.push_back(p.edge);
  }
  for (int64_t id : fixed_ids) {
    const auto it = index.find(id);
    if (it == index.end()) {
      result.error = name + ": FIX names undefined vertex " + std::to_string(id);
      return result;
    }
    graph.fixed[it->second] = true;
  }
  if (from_edges) initialise_from_edges(graph);
  result.initialised_from_edges = from_edges;
  result.graph = std::move(graph);
  return result;
}

GraphReadResult read_pose_graph(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    GraphReadResult r;
    r.error = path + ": cannot open";
    return r;
  }
  return read_pose_graph(in, path);
}

void write_g2o(const PoseGraph& graph, std::ostream& out) {
  out << std::setprecision(17);
  for (std::size_t i = 0; i < graph.poses.size(); ++i) {
    const Pose2& p = graph.poses[i];
    out << "VERTEX_SE2 " << graph.ids[i] << ' ' << p.x() << ' ' << p.y() << ' ' << p.theta()
        << '\n';
  }
  for (std::size_t i = 0; i < graph.poses.size(); ++i) {
    if (graph.fixed[i]) out << "FIX " << graph.ids[i] << '\n';
  }
  for (const Edge& e : graph.edges) {
    const Eigen::Matrix3d& m = e.information;
    out << "EDGE_SE2 " << graph.ids[e.from] << ' ' << graph.ids[e.to] << ' ' << e.T_from_to.x()
        << ' ' << e.T_from_to.y() << ' ' << e.T_from_to.theta() << ' ' << m(0, 0) << ' ' << m(0, 1)
        << ' ' << m(0, 2) << ' ' << m(1, 1) << ' ' << m(1, 2) << ' ' << m(2, 2) << '\n';
  }
}

bool write_g2o(const PoseGraph& graph, const std::string& path) {
  std::ofstream out(path);
  if (!out) return false;
  write_g2o(graph, out);
  return static_cast<bool>(out);
}

}  // namespace traverse::backend
