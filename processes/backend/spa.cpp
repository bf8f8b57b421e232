#include "spa.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "config.hpp"
#include "marginals.hpp"

namespace traverse::backend {

namespace {

Ordering ordering_of(const std::string& name) {
  if (name == "block_metis") return Ordering::kBlockMetis;
  if (name == "cholmod_default") return Ordering::kScalarDefault;
  return Ordering::kBlockAmd;
}

int factorization_of(const std::string& name) {
  if (name == "supernodal") return CHOLMOD_SUPERNODAL;
  if (name == "auto") return CHOLMOD_AUTO;
  return CHOLMOD_SIMPLICIAL;
}

}  // namespace

std::optional<std::string> validate(const SpaConfig& c) {
  ConfigCheck check;
  check.require(
      c.ordering == "block_amd" || c.ordering == "block_metis" || c.ordering == "cholmod_default",
      "ordering", "must be block_amd, block_metis or cholmod_default, not '" + c.ordering + "'");
  check.require(c.factorization == "simplicial" || c.factorization == "supernodal" ||
                    c.factorization == "auto",
                "factorization",
                "must be simplicial, supernodal or auto, not '" + c.factorization + "'");
  check.positive("max_iterations", c.max_iterations);
  check.positive("initial_lambda", c.initial_lambda);
  check.require(c.max_lambda > c.initial_lambda, "max_lambda", "must exceed initial_lambda");
  check.not_negative("relative_chi2_tolerance", c.relative_chi2_tolerance);
  check.not_negative("step_tolerance", c.step_tolerance);
  check.not_negative("gradient_tolerance", c.gradient_tolerance);
  return check.problem();
}

SpaOptimizer::SpaOptimizer(SpaConfig config)
    : config_(std::move(config)),
      system_(ordering_of(config_.ordering), factorization_of(config_.factorization)) {}

void SpaOptimizer::prepare(PoseGraph& graph) {
  graph.fix_gauge_if_free();
  block_of_.assign(graph.poses.size(), -1);
  int blocks = 0;
  for (std::size_t v = 0; v < graph.poses.size(); ++v) {
    if (!graph.fixed[v]) block_of_[v] = blocks++;
  }
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> pair_of_edge(graph.edges.size(), -1);
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    const int a = block_of_[graph.edges[k].from], b = block_of_[graph.edges[k].to];
    if (a < 0 || b < 0) continue;
    pair_of_edge[k] = static_cast<int>(pairs.size());
    pairs.emplace_back(a, b);
  }
  const std::vector<int> handles = system_.set_pattern(blocks, pairs);
  edge_handle_.assign(graph.edges.size(), -1);
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    if (pair_of_edge[k] >= 0) edge_handle_[k] = handles[pair_of_edge[k]];
  }
}

double SpaOptimizer::linearize(const PoseGraph& graph, const std::vector<Pose2>& poses,
                               Eigen::VectorXd& b) {
  system_.set_zero();
  b.setZero(3 * system_.num_blocks());
  double sum = 0.0;
  Eigen::Matrix3d J_i, J_j;
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    const Edge& e = graph.edges[k];
    const Eigen::Vector3d r = edge_error(poses[e.from], poses[e.to], e.T_from_to);
    const Eigen::Vector3d omega_r = e.information * r;
    sum += r.dot(omega_r);
    edge_jacobians(poses[e.from], poses[e.to], e.T_from_to, J_i, J_j);
    const int bi = block_of_[e.from], bj = block_of_[e.to];
    const Eigen::Matrix3d omega_Ji = e.information * J_i, omega_Jj = e.information * J_j;
    if (bi >= 0) {
      system_.add_diagonal(bi, J_i.transpose() * omega_Ji);
      b.segment<3>(3 * bi) += J_i.transpose() * omega_r;
    }
    if (bj >= 0) {
      system_.add_diagonal(bj, J_j.transpose() * omega_Jj);
      b.segment<3>(3 * bj) += J_j.transpose() * omega_r;
    }
    if (edge_handle_[k] >= 0) system_.add_off_diagonal(edge_handle_[k], J_i.transpose() * omega_Jj);
  }
  return sum;
}

double SpaOptimizer::apply_step(const std::vector<Pose2>& poses, const Eigen::VectorXd& dx,
                                std::vector<Pose2>& trial) const {
  double x_norm2 = 0.0;
  for (std::size_t v = 0; v < poses.size(); ++v) {
    const Pose2& p = poses[v];
    x_norm2 += p.vector().squaredNorm();
    const int blk = block_of_[v];
    trial[v] =
        blk < 0 ? p
                : Pose2(p.x() + dx[3 * blk], p.y() + dx[3 * blk + 1], p.theta() + dx[3 * blk + 2]);
  }
  return std::sqrt(x_norm2);
}

SpaResult SpaOptimizer::optimize(PoseGraph& graph) {
  SpaResult result;
  // An information matrix that is not positive definite rewards error along some direction: the
  // optimiser would "converge" with poses kilometres away.
  for (std::size_t k = 0; k < graph.edges.size(); ++k) {
    const Edge& e = graph.edges[k];
    if (!positive_definite(e.information)) {
      result.termination = "edge " + std::to_string(k) + " (" + std::to_string(graph.ids[e.from]) +
                           " -> " + std::to_string(graph.ids[e.to]) +
                           ") has an information matrix that is not positive definite";
      return result;
    }
  }
  prepare(graph);
  Eigen::VectorXd b, dx;
  double chi2_now = linearize(graph, graph.poses, b);
  result.initial_chi2 = result.final_chi2 = chi2_now;
  if (system_.num_blocks() == 0 || graph.edges.empty()) {
    result.converged = true;
    result.termination = "nothing to optimise";
    return result;
  }
  if (!std::isfinite(chi2_now)) {
    result.termination = "initial chi2 is not finite";
    return result;
  }
  // Damping update as in Madsen, Nielsen & Tingleff (2004), algorithm 3.16, on Marquardt's
  // scaled system H + lambda diag(H) of SPA.
  double lambda = config_.initial_lambda;
  double nu = 2.0;
  std::vector<Pose2> trial(graph.poses.size());
  while (true) {
    if (b.lpNorm<Eigen::Infinity>() < config_.gradient_tolerance) {
      result.converged = true;
      result.termination = "gradient below tolerance";
      break;
    }
    if (result.iterations >= config_.max_iterations) {
      result.termination = "iteration cap reached";
      break;
    }
    if (lambda > config_.max_lambda) {
      result.converged = true;
      result.termination = "no step lowers chi2 (damping at its limit)";
      break;
    }
    ++result.iterations;
    if (!system_.factorize(lambda) || !system_.solve(-b, dx)) {
      lambda *= nu;
      nu *= 2.0;
      continue;
    }
    const double x_norm = apply_step(graph.poses, dx, trial);
    const double chi2_trial = chi2(graph, trial);
    // Predicted decrease of the quadratic model: dx^T (lambda D dx - b).
    const double predicted = dx.dot(lambda * system_.damping_diagonal().cwiseProduct(dx) - b);
    const double rho = std::isfinite(chi2_trial) ? (chi2_now - chi2_trial) / predicted : -1.0;
    if (!std::isfinite(chi2_trial)) ++result.rejected_non_finite;
    if (rho > 0.0 && std::isfinite(rho)) {
      const double decrease = chi2_now - chi2_trial;
      graph.poses.swap(trial);
      ++result.accepted_steps;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      const double previous = chi2_now;
      chi2_now = linearize(graph, graph.poses, b);
      if (decrease <= config_.relative_chi2_tolerance * previous) {
        result.converged = true;
        result.termination = "relative chi2 decrease below tolerance";
        break;
      }
      if (dx.norm() <= config_.step_tolerance * (x_norm + config_.step_tolerance)) {
        result.converged = true;
        result.termination = "step below tolerance";
        break;
      }
    } else {
      lambda *= nu;
      nu *= 2.0;
    }
  }
  result.final_chi2 = chi2_now;
  return result;
}

std::optional<std::vector<Eigen::Matrix3d>> SpaOptimizer::marginals(PoseGraph& graph) {
  prepare(graph);
  Eigen::VectorXd b;
  linearize(graph, graph.poses, b);
  if (!system_.factorize(0.0)) return std::nullopt;
  auto blocks = diagonal_blocks_of_inverse(system_.factor(), system_.common());
  if (!blocks) return std::nullopt;
  std::vector<Eigen::Matrix3d> out(graph.poses.size(), Eigen::Matrix3d::Zero());
  for (std::size_t v = 0; v < graph.poses.size(); ++v) {
    if (block_of_[v] >= 0) out[v] = (*blocks)[block_of_[v]];
  }
  return out;
}

}  // namespace traverse::backend
