// traverse-pgo-ceres: the reference solver for traverse-pgo. The same 2D pose graph and the same
// edge residual (g2o EDGE_SE2: e = t2v(Z^-1 (Xi^-1 Xj)), angle wrapped), solved by Ceres with
// Levenberg-Marquardt and sparse normal Cholesky on SuiteSparse, run to convergence. Prints a JSON
// summary with the same keys as traverse-pgo as its last line.
#include <ceres/ceres.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>

#include "graph_io.hpp"
#include "json.hpp"
#include "version.hpp"

namespace {

// Residual r = S e with S^T S = Omega, so r^T r = e^T Omega e; Ceres minimises 0.5 sum r^T r.
struct EdgeSe2Residual {
  EdgeSe2Residual(const traverse::Pose2& Z, const Eigen::Matrix3d& information)
      : z_x(Z.x()), z_y(Z.y()), z_theta(Z.theta()) {
    sqrt_information = information.llt().matrixU();
  }

  template <class T>
  static T wrap(const T& a) {
    const T two_pi = T(2.0 * M_PI);
    return a - two_pi * ceres::floor((a + T(M_PI)) / two_pi);
  }

  template <class T>
  bool operator()(const T* xi, const T* xj, T* residual) const {
    const T a = xi[2] + T(z_theta);
    const T c = ceres::cos(a), s = ceres::sin(a);
    const double cz = std::cos(z_theta), sz = std::sin(z_theta);
    const T dx = xj[0] - xi[0], dy = xj[1] - xi[1];
    T e[3];
    e[0] = c * dx + s * dy - T(cz * z_x + sz * z_y);
    e[1] = -s * dx + c * dy - T(-sz * z_x + cz * z_y);
    e[2] = wrap(xj[2] - xi[2] - T(z_theta));
    for (int r = 0; r < 3; ++r) {
      residual[r] = T(0.0);
      for (int k = 0; k < 3; ++k) residual[r] += T(sqrt_information(r, k)) * e[k];
    }
    return true;
  }

  double z_x, z_y, z_theta;
  Eigen::Matrix3d sqrt_information;
};

// CPU time of the process [s] (all threads).
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double chi2(ceres::Problem& problem) {
  double cost = 0.0;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  return 2.0 * cost;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "traverse-pgo-ceres: reference 2D pose-graph solver on Ceres (LM, sparse normal "
      "Cholesky, SuiteSparse), same residual as traverse-pgo. JSON summary last."};
  std::string file, out_path;
  int threads = 1;
  double tolerance = 1e-10;
  app.add_option("FILE", file, "pose graph file (g2o or TORO)")->required();
  app.add_option("--out", out_path, "write the optimised graph as g2o");
  app.add_option("--threads", threads, "Ceres threads for Jacobian evaluation")
      ->capture_default_str();
  app.add_option("--tolerance", tolerance,
                 "function tolerance (relative cost decrease); gradient and parameter "
                 "tolerances are set 100 times tighter")
      ->capture_default_str();
  traverse::add_version_flag(app);
  CLI11_PARSE(app, argc, argv);

  auto read = traverse::backend::read_pose_graph(file);
  if (!read.graph) {
    std::cerr << "traverse-pgo-ceres: " << read.error << '\n';
    return 1;
  }
  traverse::backend::PoseGraph& graph = *read.graph;
  graph.fix_gauge_if_free();
  std::vector<std::array<double, 3>> x(graph.poses.size());
  for (std::size_t v = 0; v < x.size(); ++v) {
    x[v] = {graph.poses[v].x(), graph.poses[v].y(), graph.poses[v].theta()};
  }
  ceres::Problem problem;
  for (const auto& e : graph.edges) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<EdgeSe2Residual, 3, 3, 3>(
                                 new EdgeSe2Residual(e.T_from_to, e.information)),
                             nullptr, x[e.from].data(), x[e.to].data());
  }
  for (std::size_t v = 0; v < x.size(); ++v) {
    if (graph.fixed[v] && problem.HasParameterBlock(x[v].data())) {
      problem.SetParameterBlockConstant(x[v].data());
    }
  }
  const double initial_chi2 = chi2(problem);

  ceres::Solver::Options options;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  options.max_num_iterations = 100000;
  options.function_tolerance = tolerance;
  options.gradient_tolerance = tolerance * 1e-2;
  options.parameter_tolerance = tolerance * 1e-2;
  options.num_threads = threads;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = cpu_seconds();
  ceres::Solve(options, &problem, &summary);
  const double solve_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double solve_cpu_s = cpu_seconds() - cpu0;
  const double final_chi2 = chi2(problem);
  const bool converged = summary.termination_type == ceres::CONVERGENCE;
  const int iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  std::printf("ceres: chi2 %.6f -> %.6f in %d iterations (%d successful), %.3f s; %s\n",
              initial_chi2, final_chi2, iterations, summary.num_successful_steps, solve_s,
              summary.message.c_str());
  if (!out_path.empty()) {
    for (std::size_t v = 0; v < x.size(); ++v) graph.poses[v] = {x[v][0], x[v][1], x[v][2]};
    if (!traverse::backend::write_g2o(graph, out_path)) {
      std::cerr << "traverse-pgo-ceres: cannot write " << out_path << '\n';
      return 1;
    }
  }
  traverse::Json j;
  j["file"] = file;
  j["vertices"] = graph.poses.size();
  j["edges"] = graph.edges.size();
  j["initial_chi2"] = traverse::json_significant(initial_chi2, 12);
  j["final_chi2"] = traverse::json_significant(final_chi2, 12);
  j["iterations"] = iterations;
  j["accepted_steps"] = summary.num_successful_steps;
  j["converged"] = converged;
  j["termination"] = ceres::TerminationTypeToString(summary.termination_type);
  j["solve_s"] = traverse::json_fixed(solve_s, 6);
  j["solve_cpu_s"] = traverse::json_fixed(solve_cpu_s, 6);
  j["linear_solver"] =
      ceres::SparseLinearAlgebraLibraryTypeToString(summary.sparse_linear_algebra_library_type);
  j["threads"] = threads;
  std::printf("%s\n", traverse::json_line(j).c_str());
  return converged ? 0 : 3;
}
