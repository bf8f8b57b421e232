// Fuzz target: g2o and TORO pose-graph files, and what traverse-pgo does with a graph it read
// (components, gauge, a few optimiser steps, marginals). Invariant: a graph written back as g2o
// reads again with the same vertices and edges.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "graph_io.hpp"
#include "spa.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace traverse::backend;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  GraphReadResult read = read_pose_graph(in, "fuzz.g2o");
  if (!read.graph) return 0;
  PoseGraph& graph = *read.graph;
  std::ostringstream out;
  write_g2o(graph, out);
  std::istringstream back(out.str());
  const GraphReadResult again = read_pose_graph(back, "again.g2o");
  if (!again.graph || again.graph->poses.size() != graph.poses.size() ||
      again.graph->edges.size() != graph.edges.size()) {
    std::abort();
  }
  if (graph.poses.size() > 64 || graph.edges.size() > 256) return 0;
  SpaConfig config;
  config.max_iterations = 20;
  SpaOptimizer optimizer(config);
  optimizer.optimize(graph);
  optimizer.marginals(graph);
  return 0;
}
