// traverse-pgo: optimises a 2D pose graph file (g2o or TORO) with the backend's SPA optimiser,
// recovers the marginal covariance of every pose, and prints a JSON summary as its last line.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "config.hpp"
#include "graph_io.hpp"
#include "json.hpp"
#include "spa.hpp"
#include "version.hpp"

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// CPU time of the process [s] (all threads): robust against other load on the machine.
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// One line per pose; `component` says which connected component it is in: a covariance is
// relative to its component's fixed vertex, and none relates two components.
bool write_marginals(const traverse::backend::PoseGraph& graph,
                     const std::vector<Eigen::Matrix3d>& cov, const std::vector<int>& component,
                     const std::string& path) {
  std::ofstream out(path);
  if (!out) return false;
  out << "id,component,x_m,y_m,theta_rad,cov_xx_m2,cov_xy_m2,cov_xtheta_m_rad,cov_yy_m2,"
         "cov_ytheta_m_rad,cov_thetatheta_rad2\n";
  out << std::setprecision(17);
  for (std::size_t v = 0; v < graph.poses.size(); ++v) {
    const auto& p = graph.poses[v];
    const Eigen::Matrix3d& c = cov[v];
    out << graph.ids[v] << ',' << component[v] << ',' << p.x() << ',' << p.y() << ',' << p.theta()
        << ',' << c(0, 0) << ',' << c(0, 1) << ',' << c(0, 2) << ',' << c(1, 1) << ',' << c(1, 2)
        << ',' << c(2, 2) << '\n';
  }
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "traverse-pgo: Sparse Pose Adjustment (Levenberg-Marquardt on CHOLMOD) of a 2D pose graph\n"
      "in g2o (VERTEX_SE2/EDGE_SE2) or TORO (VERTEX2/EDGE2) format, with the marginal covariance\n"
      "of every pose. Prints a JSON summary as the last line."};
  std::string file, out_path, marginals_path, config_path;
  bool skip_marginals = false;
  app.add_option("FILE", file, "pose graph file (g2o or TORO)")->required();
  app.add_option("--out", out_path, "write the optimised graph as g2o");
  app.add_option("--marginals", marginals_path,
                 "write per-pose marginal covariances (world frame, x y theta) as CSV");
  app.add_flag("--no-marginals", skip_marginals, "skip the covariance recovery");
  app.add_option("--config", config_path, "YAML optimiser settings (see configs/pgo.yaml)");
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  traverse::backend::SpaConfig config;
  if (!config_path.empty()) {
    try {
      traverse::load_config(config_path, config);
      if (const auto problem = traverse::backend::validate(config)) {
        throw traverse::ConfigError(config_path + ": " + *problem);
      }
    } catch (const traverse::ConfigError& e) {
      std::cerr << "traverse-pgo: " << e.what() << '\n';
      return traverse::kConfigErrorExitCode;
    }
  }
  auto read = traverse::backend::read_pose_graph(file);
  if (!read.graph) {
    std::cerr << "traverse-pgo: " << read.error << '\n';
    return 1;
  }
  traverse::backend::PoseGraph& graph = *read.graph;
  int components = 0;
  const std::vector<int> component = traverse::backend::components(graph, &components);
  if (components > 1) {
    std::printf("graph: %d connected components, one vertex fixed in each\n", components);
  }

  traverse::backend::SpaOptimizer optimizer(config);
  auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  const traverse::backend::SpaResult result = optimizer.optimize(graph);
  const double solve_s = seconds_since(t0);
  const double solve_cpu_s = cpu_seconds() - cpu0;
  std::printf(
      "graph: %zu vertices, %zu edges; chi2 %.6f -> %.6f in %d iterations (%d accepted), "
      "%.3f s; %s\n",
      graph.poses.size(), graph.edges.size(), result.initial_chi2, result.final_chi2,
      result.iterations, result.accepted_steps, solve_s, result.termination.c_str());

  double marginals_s = 0.0;
  std::size_t marginals_recovered = 0;
  if (!skip_marginals) {
    t0 = std::chrono::steady_clock::now();
    const auto cov = optimizer.marginals(graph);
    marginals_s = seconds_since(t0);
    if (!cov) {
      std::cerr << "traverse-pgo: marginals failed: the information matrix is singular at the "
                   "optimised poses\n";
      return 1;
    }
    marginals_recovered = cov->size();
    std::printf("marginals: %zu poses in %.3f s (factor non-zeros %ld)\n", cov->size(), marginals_s,
                optimizer.system().nnz_l());
    if (!marginals_path.empty() && !write_marginals(graph, *cov, component, marginals_path)) {
      std::cerr << "traverse-pgo: cannot write " << marginals_path << '\n';
      return 1;
    }
  }
  if (!out_path.empty() && !traverse::backend::write_g2o(graph, out_path)) {
    std::cerr << "traverse-pgo: cannot write " << out_path << '\n';
    return 1;
  }
  traverse::Json j;
  j["file"] = file;
  j["vertices"] = graph.poses.size();
  j["edges"] = graph.edges.size();
  j["components"] = components;
  j["initialised_from_edges"] = read.initialised_from_edges;
  j["initial_chi2"] = traverse::json_significant(result.initial_chi2, 12);
  j["final_chi2"] = traverse::json_significant(result.final_chi2, 12);
  j["iterations"] = result.iterations;
  j["accepted_steps"] = result.accepted_steps;
  j["converged"] = result.converged;
  j["termination"] = result.termination;
  j["rejected_non_finite"] = result.rejected_non_finite;
  j["solve_s"] = traverse::json_fixed(solve_s, 6);
  j["solve_cpu_s"] = traverse::json_fixed(solve_cpu_s, 6);
  j["marginals"] = marginals_recovered;
  j["marginals_s"] = traverse::json_fixed(marginals_s, 6);
  j["symbolic_analyses"] = optimizer.system().analyses();
  j["factor_nnz"] = optimizer.system().nnz_l();
  std::printf("%s\n", traverse::json_line(j).c_str());
  return result.converged ? 0 : 3;
}
