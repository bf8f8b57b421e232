// The traverse-pgo and traverse-pgo-ceres programs on small graphs written by the test.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../backend/test_graphs.hpp"
#include "graph_io.hpp"
#include "json.hpp"

namespace traverse::backend {
namespace {

namespace fs = std::filesystem;

struct ProgramRun {
  int exit_code;
  std::string out;  // stdout and stderr
};

ProgramRun run(const std::string& args) {
  const std::string cmd = args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ProgramRun r{-1, ""};
  if (!pipe) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) r.out += buf;
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string last_line(const std::string& s) {
  std::string t = s;
  while (!t.empty() && t.back() == '\n') t.pop_back();
  return t.substr(t.rfind('\n') == std::string::npos ? 0 : t.rfind('\n') + 1);
}

// The value of a key of the JSON summary line as JSON text ("" when absent).
std::string json_value(const std::string& json, const std::string& key) {
  const traverse::Json j = traverse::Json::parse(json, nullptr, false);
  return !j.is_discarded() && j.is_object() && j.contains(key) ? j[key].dump() : "";
}

class PgoProgram : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("traverse_pgo_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    graph_path_ = (dir_ / "walk.g2o").string();
    ASSERT_TRUE(write_g2o(testing::make_walk_graph(100, 17, 0.05), graph_path_));
  }
  void TearDown() override { fs::remove_all(dir_); }

  const std::string pgo_ = std::string(TRAVERSE_BIN_DIR) + "/traverse-pgo";
  const std::string ceres_ = std::string(TRAVERSE_BIN_DIR) + "/traverse-pgo-ceres";
  fs::path dir_;
  std::string graph_path_;
};

TEST_F(PgoProgram, HelpExitsZero) {
  EXPECT_EQ(run(pgo_ + " --help").exit_code, 0);
  EXPECT_EQ(run(ceres_ + " --help").exit_code, 0);
}

TEST_F(PgoProgram, OptimisesWritesGraphAndMarginals) {
  const std::string out = (dir_ / "opt.g2o").string(), csv = (dir_ / "marg.csv").string();
  const ProgramRun r = run(pgo_ + " " + graph_path_ + " --out " + out + " --marginals " + csv);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::string json = last_line(r.out);
  for (const char* key : {"vertices", "edges", "initial_chi2", "final_chi2", "iterations",
                          "converged", "solve_s", "marginals_s"}) {
    EXPECT_NE(json_value(json, key), "") << key << " missing in " << json;
  }
  EXPECT_EQ(json_value(json, "vertices"), "100");
  EXPECT_EQ(json_value(json, "converged"), "true");
  EXPECT_EQ(json_value(json, "marginals"), "100");
  const double final_chi2 = std::stod(json_value(json, "final_chi2"));
  EXPECT_LT(final_chi2, std::stod(json_value(json, "initial_chi2")));

  // The written graph is the optimum: its chi2 is the reported one.
  const auto written = read_pose_graph(out);
  ASSERT_TRUE(written.graph) << written.error;
  EXPECT_NEAR(chi2(*written.graph), final_chi2, 1e-6 * final_chi2);

  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("id,component,x_m,y_m,theta_rad,cov_xx_m2", 0), 0u);
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 100);
}

TEST_F(PgoProgram, ReadsToroFiles) {
  const auto g = read_pose_graph(graph_path_);
  ASSERT_TRUE(g.graph);
  const std::string toro = (dir_ / "walk.graph").string();
  {
    std::ofstream out(toro);
    out.precision(17);
    for (std::size_t v = 0; v < g.graph->poses.size(); ++v) {
      const Pose2& p = g.graph->poses[v];
      out << "VERTEX2 " << v << ' ' << p.x() << ' ' << p.y() << ' ' << p.theta() << '\n';
    }
    for (const Edge& e : g.graph->edges) {
      const Eigen::Matrix3d& m = e.information;
      out << "EDGE2 " << e.from << ' ' << e.to << ' ' << e.T_from_to.x() << ' ' << e.T_from_to.y()
          << ' ' << e.T_from_to.theta() << ' ' << m(0, 0) << ' ' << m(0, 1) << ' ' << m(1, 1) << ' '
          << m(2, 2) << ' ' << m(0, 2) << ' ' << m(1, 2) << '\n';
    }
  }
  const ProgramRun a = run(pgo_ + " " + graph_path_ + " --no-marginals");
  const ProgramRun b = run(pgo_ + " " + toro + " --no-marginals");
  ASSERT_EQ(b.exit_code, 0) << b.out;
  EXPECT_EQ(json_value(last_line(a.out), "initial_chi2"),
            json_value(last_line(b.out), "initial_chi2"));
  EXPECT_EQ(json_value(last_line(a.out), "final_chi2"), json_value(last_line(b.out), "final_chi2"));
}

TEST_F(PgoProgram, CeresReferenceAgreesWithOurs) {
  const ProgramRun ours = run(pgo_ + " " + graph_path_);
  const ProgramRun ref = run(ceres_ + " " + graph_path_);
  ASSERT_EQ(ours.exit_code, 0) << ours.out;
  ASSERT_EQ(ref.exit_code, 0) << ref.out;
  const std::string a = last_line(ours.out), b = last_line(ref.out);
  EXPECT_EQ(json_value(b, "converged"), "true");
  const double init_a = std::stod(json_value(a, "initial_chi2"));
  const double init_b = std::stod(json_value(b, "initial_chi2"));
  EXPECT_NEAR(init_a, init_b, 1e-9 * init_b);  // the same residual definition
  const double final_a = std::stod(json_value(a, "final_chi2"));
  const double final_b = std::stod(json_value(b, "final_chi2"));
  EXPECT_NEAR(final_a, final_b, 1e-6 * final_b);
}

TEST_F(PgoProgram, BadFileNamesTheLine) {
  const std::string bad = (dir_ / "bad.g2o").string();
  std::ofstream(bad) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nEDGE_SE2 0 1 1 0\n";
  const ProgramRun r = run(pgo_ + " " + bad);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("bad.g2o:3:"), std::string::npos) << r.out;
}

TEST_F(PgoProgram, RefusesAnInformationMatrixNotPositiveDefiniteNamingTheLine) {
  // Before: "converged": true, chi2 4e11, poses 45 km away, exit 0.
  const std::string path = (dir_ / "bad.g2o").string();
  std::ofstream(path) << "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\nVERTEX_SE2 2 2 0 0\n"
                         "EDGE_SE2 0 1 1 0 0 100 0 0 100 0 100\n"
                         "EDGE_SE2 1 2 1 0 0 -1000 0 0 1000 0 1000\n";
  const ProgramRun r = run(pgo_ + " " + path);
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("bad.g2o:5: information matrix of edge 1 -> 2 is not positive definite"),
            std::string::npos)
      << r.out;
}

TEST_F(PgoProgram, EmptyFileGetsAClearError) {
  const std::string path = (dir_ / "empty.g2o").string();
  std::ofstream(path) << "";
  const ProgramRun r = run(pgo_ + " " + path);
  EXPECT_NE(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("no vertices and no edges"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("singular"), std::string::npos) << r.out;
}

TEST_F(PgoProgram, DisconnectedGraphIsSolvedPerComponent) {
  // Before: marginals of 4.7e28 m^2, unflagged.
  PoseGraph a = testing::make_walk_graph(40, 3, 0.05);
  PoseGraph g = a;
  const int n = static_cast<int>(a.poses.size());
  for (int k = 0; k < n; ++k) g.add_vertex(500 + k, a.poses[k] * Pose2(0, 30, 0));
  for (Edge e : a.edges) {
    e.from += n;
    e.to += n;
    g.edges.push_back(e);
  }
  const std::string path = (dir_ / "two.g2o").string(), csv = (dir_ / "two.csv").string();
  ASSERT_TRUE(write_g2o(g, path));
  const ProgramRun r = run(pgo_ + " " + path + " --marginals " + csv);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::string json = last_line(r.out);
  EXPECT_EQ(json_value(json, "components"), "2") << json;
  EXPECT_EQ(json_value(json, "converged"), "true") << json;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  int rows = 0, second = 0;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string id, component, x, y, theta, cxx;
    std::getline(ss, id, ',');
    std::getline(ss, component, ',');
    std::getline(ss, x, ',');
    std::getline(ss, y, ',');
    std::getline(ss, theta, ',');
    std::getline(ss, cxx, ',');
    EXPECT_LT(std::stod(cxx), 1.0) << line;  // m^2: relative to the component's fixed vertex
    second += component == "1";
    ++rows;
  }
  EXPECT_EQ(rows, 2 * n);
  EXPECT_EQ(second, n);
}

TEST_F(PgoProgram, ReadsEdgeOnlyFiles) {
  // The SE-Sync graphs (city10000) have no VERTEX lines: the first 2,000 edges of it.
  const std::string path = (dir_ / "city-edges.g2o").string();
  ASSERT_EQ(
      run("grep -m 2000 '^EDGE_SE2' ../shared/data/posegraphs/city10000.g2o > " + path).exit_code,
      0);
  const ProgramRun r = run(pgo_ + " " + path + " --no-marginals");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const std::string json = last_line(r.out);
  EXPECT_EQ(json_value(json, "initialised_from_edges"), "true") << json;
  EXPECT_EQ(json_value(json, "converged"), "true") << json;
  EXPECT_EQ(json_value(json, "components"), "1") << json;
  // The spanning tree starts from the odometry chain's own composition: chi2 only falls.
  EXPECT_LE(std::stod(json_value(json, "final_chi2")), std::stod(json_value(json, "initial_chi2")));
}

TEST_F(PgoProgram, UnknownConfigKeyIsAnError) {
  const std::string cfg = (dir_ / "pgo.yaml").string();
  std::ofstream(cfg) << "max_iteration: 5\n";
  const ProgramRun r = run(pgo_ + " " + graph_path_ + " --config " + cfg);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("max_iteration"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace traverse::backend
