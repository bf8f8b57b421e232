// The sparse normal equations of a pose graph, (H + lambda diag(H)) dx = -b with 3x3 blocks, held
// in CHOLMOD's compressed-column form (upper triangle only, as CHOLMOD reads symmetric matrices)
// and solved by sparse Cholesky. As in SPA (Konolige et al. 2010, section IV), H is assembled
// directly into the compressed-column arrays: the position of every block is computed once per
// sparsity pattern, so a linearisation only zeroes and accumulates values. The symbolic analysis
// (fill- reducing ordering and elimination tree, cholmod_analyze) is done once per pattern and
// reused by every numeric factorisation until the pattern changes. When the pattern changes only
// by blocks appended at the end and linked to the newest old block (a growing chain of key poses
// between loop closures), the block ordering of the previous analysis is kept and extended by the
// new blocks instead of being recomputed; CHOLMOD then redoes only the elimination tree and
// column counts (linear in the non-zeros). A new edge between old blocks (a loop closure), or a
// quarter more blocks than at the last full ordering, orders afresh.
#pragma once

#include <cholmod.h>

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace traverse::backend {

// Fill-reducing ordering for the symbolic analysis.
enum class Ordering {
  kScalarDefault,  // CHOLMOD's default strategy on the scalar matrix (AMD, METIS if fill is bad)
  kBlockAmd,       // AMD on the graph of 3x3 blocks, expanded to scalars
  kBlockMetis,     // METIS nested dissection on the graph of 3x3 blocks, expanded to scalars
};

class BlockCholesky {
 public:
  // The default simplicial LDL' measured about twice as fast as the supernodal factorisation on
  // city10000 (pose-graph factors have small supernodes); see scripts/bench/pgo.sh.
  // factorization: CHOLMOD_SIMPLICIAL, CHOLMOD_SUPERNODAL or CHOLMOD_AUTO.
  explicit BlockCholesky(Ordering ordering = Ordering::kBlockAmd,
                         int factorization = CHOLMOD_SIMPLICIAL);
  ~BlockCholesky();
  BlockCholesky(const BlockCholesky&) = delete;
  BlockCholesky& operator=(const BlockCholesky&) = delete;

  // Sets the block pattern: num_blocks 3x3 diagonal blocks plus the off-diagonal blocks named by
  // pairs (i != j, either order, repeats allowed). Returns one handle per pair for
  // add_off_diagonal. Keeps the symbolic analysis when the pattern equals the previous one.
  std::vector<int> set_pattern(int num_blocks, const std::vector<std::pair<int, int>>& pairs);

  int num_blocks() const { return num_blocks_; }
  // Zeroes all values (pattern kept).
  void set_zero();
  // H_ii += M (M symmetric; its upper triangle is used).
  void add_diagonal(int i, const Eigen::Matrix3d& M);
  // Adds M to the off-diagonal block of a pair given to set_pattern, M = H_ij for that pair's
  // (i, j) in the order given there.
  void add_off_diagonal(int handle, const Eigen::Matrix3d& M);

  // Numeric factorisation of H + lambda D, D = diag(H) clamped below at 1e-6 (Marquardt's
  // scaling, as in SPA); lambda = 0 factors H itself. False when not positive definite.
  bool factorize(double lambda);
  // Solves (H + lambda D) x = rhs with the last factorisation.
  bool solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x);

  // y = H x (without damping), from the stored upper triangle.
  Eigen::VectorXd multiply(const Eigen::VectorXd& x) const;
  // Diagonal of H, and the damping matrix D = max(diag(H), 1e-6) of the last factorize.
  Eigen::VectorXd diagonal() const;
  const Eigen::VectorXd& damping_diagonal() const { return damping_; }

  // The last numeric factor (CHOLMOD ordering and storage); null before factorize.
  const cholmod_factor* factor() const { return factor_; }
  cholmod_common* common() { return &common_; }
  // Number of symbolic analyses done so far (for checking reuse), and how many of them reused
  // the previous ordering extended by appended blocks.
  int analyses() const { return analyses_; }
  int orderings_reused() const { return orderings_reused_; }
  // Non-zeros of the upper triangle of H and of the last factor L.
  long nnz_h() const;
  long nnz_l() const;

 private:
  struct Slot {
    int column_block;  // j: the block column holding the stored (upper) block
    int row_slot;      // position of the row block among column j's upper neighbours
    bool transposed;   // the pair was given as (j, i): add M^T
  };
  void free_all();
  bool factorize_damped();
  bool analyse();
  // Whether the pattern only appends blocks to the last analysed one (see the top).
  bool extends_last_ordering() const;
  // Fill-reducing ordering of the block graph (AMD or METIS).
  bool order_blocks(std::vector<int>& block_perm);

  Ordering ordering_;
  cholmod_common common_;
  cholmod_sparse* matrix_ = nullptr;
  cholmod_factor* factor_ = nullptr;
  int num_blocks_ = 0;
  std::vector<std::vector<int>> upper_neighbours_;  // per block column, sorted row blocks < j
  std::vector<Slot> slots_;
  Eigen::VectorXd damping_;
  int analyses_ = 0;
  int orderings_reused_ = 0;
  bool analysed_ = false;
  // The pattern and block ordering of the last analysis, and the size at the last full ordering.
  std::vector<std::vector<int>> ordered_upper_;
  std::vector<int> block_perm_;
  int fully_ordered_blocks_ = 0;
};

}  // namespace traverse::backend
