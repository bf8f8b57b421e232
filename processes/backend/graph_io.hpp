// Reading and writing 2D pose graphs in the two common text formats.
//
// g2o:  VERTEX_SE2 id x y theta
//       EDGE_SE2 i j dx dy dtheta I11 I12 I13 I22 I23 I33   (upper triangle, row-major)
//       FIX id                                               (optional gauge)
// TORO: VERTEX2 id x y theta
//       EDGE2 i j dx dy dtheta I11 I12 I22 I33 I13 I23
// Lengths in metres, angles in radians. Blank lines and lines starting with '#' are skipped; any
// other unknown or malformed line is an error naming the file and line number, and so is an
// information matrix that is not symmetric positive definite (it would make the optimiser report
// convergence with poses kilometres away). A file with edges but no vertex lines at all (the
// SE-Sync benchmark graphs) gets a vertex per id, initialised by composing the edges along a
// spanning tree; an empty file is an error.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>

#include "pose_graph.hpp"

namespace traverse::backend {

struct GraphReadResult {
  std::optional<PoseGraph> graph;       // empty on error
  std::string error;                    // "FILE:LINE: what is wrong" when graph is empty
  bool initialised_from_edges = false;  // no vertex lines: poses composed along a spanning tree
};

// Reads a g2o or TORO file (the record tags decide; both may be mixed). Vertex ids may be
// arbitrary integers; edges must name vertices defined anywhere in the file.
GraphReadResult read_pose_graph(const std::string& path);
GraphReadResult read_pose_graph(std::istream& in, const std::string& name);

// Writes the graph as g2o (VERTEX_SE2, FIX, EDGE_SE2) with 17 significant digits. Returns false
// when the file cannot be written.
bool write_g2o(const PoseGraph& graph, const std::string& path);
void write_g2o(const PoseGraph& graph, std::ostream& out);

}  // namespace traverse::backend
