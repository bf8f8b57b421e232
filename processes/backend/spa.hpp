// Sparse Pose Adjustment (Konolige et al., "Efficient Sparse Pose Adjustment for 2D Mapping",
// IROS 2010): Levenberg-Marquardt on a 2D pose graph, the normal equations assembled directly in
// compressed-column form and solved by sparse Cholesky (CHOLMOD, see block_cholesky.hpp).
//
// Each iteration solves (H + lambda diag(H)) dx = -b, H = sum J^T Omega J, b = sum J^T Omega e, and
// updates the damping by the gain ratio as in Nielsen (1999) / Madsen, Nielsen & Tingleff,
// "Methods for non-linear least squares problems" (2004), section 3.2. The first vertex (or the
// vertices marked fixed) of each connected component is held constant, which fixes the gauge; an
// edge whose information matrix is not positive definite stops it before the first step. It stops
// on convergence (relative chi2 decrease, step size, or gradient below tolerance), not on an
// iteration count; the cap is only a guard and reaching it is reported as not converged. A step
// whose cost is NaN or infinite is rejected like any other failed step, so the state always stays
// the last good one.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "block_cholesky.hpp"
#include "pose_graph.hpp"

namespace traverse::backend {

struct SpaConfig {
  int max_iterations = 100000;               // guard only; reaching it is "not converged"
  double relative_chi2_tolerance = 1e-10;    // stop when an accepted step lowers chi2 by less
  double step_tolerance = 1e-12;             // stop when |dx| < tol * (|x| + tol)
  double gradient_tolerance = 1e-12;         // stop when max |b| < tol (units of chi2 per m/rad)
  double initial_lambda = 1e-4;              // damping of the first step (relative to diag(H))
  double max_lambda = 1e32;                  // steps this damped cannot lower chi2: stop
  std::string ordering = "block_amd";        // block_amd, block_metis or cholmod_default
  std::string factorization = "simplicial";  // simplicial, supernodal, or auto (CHOLMOD decides)

  template <class V>
  void visit(V& v) {
    v("max_iterations", max_iterations);
    v("relative_chi2_tolerance", relative_chi2_tolerance);
    v("step_tolerance", step_tolerance);
    v("gradient_tolerance", gradient_tolerance);
    v("initial_lambda", initial_lambda);
    v("max_lambda", max_lambda);
    v("ordering", ordering);
    v("factorization", factorization);
  }
};

// An error message when a value of the config is out of range, empty when it is valid.
std::optional<std::string> validate(const SpaConfig& config);

struct SpaResult {
  double initial_chi2 = 0.0;
  double final_chi2 = 0.0;
  int iterations = 0;  // linear solves (accepted and rejected steps)
  int accepted_steps = 0;
  bool converged = false;
  std::string termination;      // why it stopped
  int rejected_non_finite = 0;  // steps whose cost was NaN/inf (state kept)
};

class SpaOptimizer {
 public:
  // The config must pass validate().
  explicit SpaOptimizer(SpaConfig config = {});

  // Optimises graph.poses in place (fixes the first vertex of every component with none fixed).
  SpaResult optimize(PoseGraph& graph);

  // Marginal covariance of every vertex at the current poses, in the world frame on
  // (x [m], y [m], theta [rad]): the 3x3 diagonal blocks of H^-1 recovered from the sparse
  // Cholesky factor (see marginals.hpp), each relative to its component's fixed vertex (nothing
  // relates two components). Fixed vertices get zero. Empty if H is singular.
  std::optional<std::vector<Eigen::Matrix3d>> marginals(PoseGraph& graph);

  const BlockCholesky& system() const { return system_; }

 private:
  // Assigns variable blocks and sets the pattern (keeping the analysis if unchanged).
  void prepare(PoseGraph& graph);
  // trial = poses + dx on the free vertices; returns |poses| on (x, y, theta).
  double apply_step(const std::vector<Pose2>& poses, const Eigen::VectorXd& dx,
                    std::vector<Pose2>& trial) const;
  // Assembles H and b at poses; returns chi2.
  double linearize(const PoseGraph& graph, const std::vector<Pose2>& poses, Eigen::VectorXd& b);

  SpaConfig config_;
  BlockCholesky system_;
  std::vector<int> block_of_;     // vertex index -> variable block, -1 if fixed
  std::vector<int> edge_handle_;  // edge -> off-diagonal handle, -1 if an end is fixed
};

}  // namespace traverse::backend
