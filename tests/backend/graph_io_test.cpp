#include "graph_io.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace traverse::backend {
namespace {

GraphReadResult parse(const std::string& text) {
  std::istringstream in(text);
  return read_pose_graph(in, "test.g2o");
}

TEST(GraphIo, ReadsG2oWithUpperTriangleInformation) {
  const auto r = parse(
      "# comment\n"
      "VERTEX_SE2 5 0 0 0\n"
      "\n"
      "VERTEX_SE2 7 1.5 -2 0.25\n"
      "EDGE_SE2 5 7 1 2 0.3 11 12 13 22 23 33\n");
  ASSERT_TRUE(r.graph) << r.error;
  const PoseGraph& g = *r.graph;
  ASSERT_EQ(g.poses.size(), 2u);
  ASSERT_EQ(g.edges.size(), 1u);
  EXPECT_EQ(g.ids[1], 7);
  EXPECT_DOUBLE_EQ(g.poses[1].y(), -2.0);
  EXPECT_EQ(g.edges[0].from, 0);
  EXPECT_EQ(g.edges[0].to, 1);
  EXPECT_DOUBLE_EQ(g.edges[0].T_from_to.theta(), 0.3);
  Eigen::Matrix3d expected;
  expected << 11, 12, 13, 12, 22, 23, 13, 23, 33;
  EXPECT_EQ(g.edges[0].information, expected);
}

TEST(GraphIo, ReadsToroInformationOrder) {
  // TORO: I11 I12 I22 I33 I13 I23.
  const auto r = parse("VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0 11 12 22 33 13 23\n");
  ASSERT_TRUE(r.graph) << r.error;
  Eigen::Matrix3d expected;
  expected << 11, 12, 13, 12, 22, 23, 13, 23, 33;
  EXPECT_EQ(r.graph->edges[0].information, expected);
}

TEST(GraphIo, EdgesMayPrecedeVerticesAndFixIsRead) {
  const auto r = parse(
      "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\nVERTEX_SE2 1 0 0 0\n"
      "VERTEX_SE2 2 1 0 0\nFIX 2\n");
  ASSERT_TRUE(r.graph) << r.error;
  EXPECT_FALSE(r.graph->fixed[0]);
  EXPECT_TRUE(r.graph->fixed[1]);
}

TEST(GraphIo, BadLinesNameTheLine) {
  auto r = parse("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0\n");
  EXPECT_FALSE(r.graph);
  EXPECT_NE(r.error.find("test.g2o:2:"), std::string::npos) << r.error;

  r = parse("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 x\n");
  EXPECT_NE(r.error.find("test.g2o:3:"), std::string::npos) << r.error;

  r = parse("VERTEX_SE2 0 0 0 0\nVERTEX_XY 1 0 0\n");
  EXPECT_NE(r.error.find("test.g2o:2: unsupported record 'VERTEX_XY'"), std::string::npos)
      << r.error;

  r = parse("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 0 1 0 0\n");
  EXPECT_NE(r.error.find("test.g2o:2: vertex 0 defined twice"), std::string::npos) << r.error;

  r = parse("VERTEX_SE2 0 0 0 0\n\nEDGE_SE2 0 9 1 0 0 1 0 0 1 0 1\n");
  EXPECT_NE(r.error.find("test.g2o:3: edge names undefined vertex 9"), std::string::npos)
      << r.error;

  r = parse("VERTEX_SE2 0 0 0 0 17\n");
  EXPECT_NE(r.error.find("test.g2o:1:"), std::string::npos) << r.error;
}

TEST(GraphIo, InformationNotPositiveDefiniteNamesTheEdgesLine) {
  const auto r = parse(
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n# a comment\n"
      "EDGE_SE2 0 1 1 0 0 -1000 0 0 1000 0 1000\n");
  EXPECT_FALSE(r.graph);
  EXPECT_NE(r.error.find("test.g2o:4: information matrix of edge 0 -> 1 is not positive definite"),
            std::string::npos)
      << r.error;
}

TEST(GraphIo, EmptyFileSaysSo) {
  for (const char* text : {"", "\n# nothing\n"}) {
    const auto r = parse(text);
    EXPECT_FALSE(r.graph);
    EXPECT_NE(r.error.find("no vertices and no edges"), std::string::npos) << r.error;
  }
}

TEST(GraphIo, EdgesAloneAreInitialisedAlongASpanningTree) {
  // The SE-Sync graphs have no VERTEX lines.
  const auto r = parse(
      "EDGE_SE2 4 7 1 0 1.5707963267948966 1 0 0 1 0 1\n"
      "EDGE_SE2 7 9 2 0 0 1 0 0 1 0 1\n");
  ASSERT_TRUE(r.graph) << r.error;
  EXPECT_TRUE(r.initialised_from_edges);
  const PoseGraph& g = *r.graph;
  EXPECT_EQ(g.ids, (std::vector<int64_t>{4, 7, 9}));
  EXPECT_NEAR(g.poses[2].x(), 1.0, 1e-12);  // 1 m ahead, turned left, then 2 m ahead
  EXPECT_NEAR(g.poses[2].y(), 2.0, 1e-12);
  // With vertex lines, an edge to an undefined vertex stays an error.
  EXPECT_FALSE(parse("VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 9 1 0 0 1 0 0 1 0 1\n").graph);
}

TEST(GraphIo, MissingFileIsAnError) {
  const auto r = read_pose_graph(std::string("/nonexistent/graph.g2o"));
  EXPECT_FALSE(r.graph);
  EXPECT_NE(r.error.find("cannot open"), std::string::npos);
}

TEST(GraphIo, WriteThenReadRoundTrips) {
  PoseGraph g;
  g.add_vertex(3, Pose2(1.0 / 3.0, -2.0 / 7.0, 0.1), true);
  g.add_vertex(8, Pose2(4.0, 5.0, -3.0));
  Eigen::Matrix3d info;
  info << 2, 0.1, 0.2, 0.1, 3, 0.3, 0.2, 0.3, 4;
  g.edges.push_back({0, 1, Pose2(0.7, 0.1, 1.0 / 3.0), info});
  std::stringstream s;
  write_g2o(g, s);
  const auto r = read_pose_graph(s, "roundtrip");
  ASSERT_TRUE(r.graph) << r.error;
  EXPECT_EQ(r.graph->ids, g.ids);
  EXPECT_EQ(r.graph->fixed, g.fixed);
  EXPECT_EQ(r.graph->poses[0].x(), g.poses[0].x());
  EXPECT_EQ(r.graph->poses[1].theta(), g.poses[1].theta());
  EXPECT_EQ(r.graph->edges[0].information, info);
  EXPECT_EQ(r.graph->edges[0].T_from_to.theta(), g.edges[0].T_from_to.theta());
}

TEST(GraphIo, ReadsTheManhattanBenchmark) {
  const auto r = read_pose_graph(std::string("../shared/data/posegraphs/input_M3500_g2o.g2o"));
  ASSERT_TRUE(r.graph) << r.error;
  EXPECT_EQ(r.graph->poses.size(), 3500u);
  EXPECT_EQ(r.graph->edges.size(), 5453u);
}

}  // namespace
}  // namespace traverse::backend
