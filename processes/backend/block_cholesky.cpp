#include "block_cholesky.hpp"

#include <algorithm>
#include <cstring>

namespace traverse::backend {

BlockCholesky::BlockCholesky(Ordering ordering, int factorization) : ordering_(ordering) {
  cholmod_start(&common_);
  common_.print = 0;  // core code never prints; failures come back as return values
  common_.error_handler = nullptr;
  common_.supernodal = factorization;
}

BlockCholesky::~BlockCholesky() {
  free_all();
  cholmod_finish(&common_);
}

void BlockCholesky::free_all() {
  if (factor_) cholmod_free_factor(&factor_, &common_);
  if (matrix_) cholmod_free_sparse(&matrix_, &common_);
  analysed_ = false;
}

std::vector<int> BlockCholesky::set_pattern(int num_blocks,
                                            const std::vector<std::pair<int, int>>& pairs) {
  std::vector<std::vector<int>> upper(num_blocks);
  for (const auto& [a, b] : pairs) upper[std::max(a, b)].push_back(std::min(a, b));
  for (auto& rows : upper) {
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  }
  std::vector<int> handles(pairs.size());
  slots_.clear();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto [a, b] = pairs[k];
    const int j = std::max(a, b), i = std::min(a, b);
    const auto& rows = upper[j];
    const int slot = static_cast<int>(std::lower_bound(rows.begin(), rows.end(), i) - rows.begin());
    slots_.push_back({j, slot, a > b});
    handles[k] = static_cast<int>(k);
  }
  if (matrix_ && num_blocks == num_blocks_ && upper == upper_neighbours_) return handles;

  // A new pattern: rebuild the column structure and forget the analysis.
  free_all();
  num_blocks_ = num_blocks;
  upper_neighbours_ = std::move(upper);
  const std::size_t n = 3 * static_cast<std::size_t>(num_blocks);
  std::size_t nnz = 0;
  for (const auto& rows : upper_neighbours_) nnz += 9 * rows.size() + 6;
  matrix_ = cholmod_allocate_sparse(n, n, nnz, /*sorted=*/1, /*packed=*/1, /*stype=*/1,
                                    CHOLMOD_REAL, &common_);
  auto* p = static_cast<int*>(matrix_->p);
  auto* ri = static_cast<int*>(matrix_->i);
  int pos = 0;
  for (int j = 0; j < num_blocks; ++j) {
    for (int k = 0; k < 3; ++k) {
      p[3 * j + k] = pos;
      for (int i : upper_neighbours_[j]) {
        for (int r = 0; r < 3; ++r) ri[pos++] = 3 * i + r;
      }
      for (int r = 0; r <= k; ++r) ri[pos++] = 3 * j + r;
    }
  }
  p[n] = pos;
  set_zero();
  return handles;
}

void BlockCholesky::set_zero() {
  if (matrix_)
    std::memset(matrix_->x, 0, sizeof(double) * static_cast<int*>(matrix_->p)[matrix_->ncol]);
}

void BlockCholesky::add_diagonal(int j, const Eigen::Matrix3d& M) {
  const auto* p = static_cast<const int*>(matrix_->p);
  auto* x = static_cast<double*>(matrix_->x);
  const int off = 3 * static_cast<int>(upper_neighbours_[j].size());
  for (int k = 0; k < 3; ++k) {
    double* col = x + p[3 * j + k] + off;
    for (int r = 0; r <= k; ++r) col[r] += M(r, k);
  }
}

void BlockCholesky::add_off_diagonal(int handle, const Eigen::Matrix3d& M) {
  const Slot& s = slots_[handle];
  const auto* p = static_cast<const int*>(matrix_->p);
  auto* x = static_cast<double*>(matrix_->x);
  for (int k = 0; k < 3; ++k) {
    double* col = x + p[3 * s.column_block + k] + 3 * s.row_slot;
    for (int r = 0; r < 3; ++r) col[r] += s.transposed ? M(k, r) : M(r, k);
  }
}

bool BlockCholesky::factorize(double lambda) {
  if (!matrix_) return false;
  // Damp in place on the stored diagonal (the last entry of each column), restore afterwards.
  const auto* p = static_cast<const int*>(matrix_->p);
  auto* x = static_cast<double*>(matrix_->x);
  const std::size_t n = matrix_->ncol;
  damping_.resize(n);
  for (std::size_t c = 0; c < n; ++c) {
    double& d = x[p[c + 1] - 1];
    damping_[c] = std::max(d, 1e-6);
    d += lambda * damping_[c];
  }
  const bool ok = factorize_damped();
  for (std::size_t c = 0; c < n; ++c) x[p[c + 1] - 1] -= lambda * damping_[c];
  return ok;
}

bool BlockCholesky::factorize_damped() {
  if (!analysed_ && !analyse()) return false;
  const int ok = cholmod_factorize(matrix_, factor_, &common_);
  return ok && common_.status == CHOLMOD_OK && factor_->minor == factor_->n;
}

bool BlockCholesky::extends_last_ordering() const {
  const int nb = num_blocks_, old = static_cast<int>(ordered_upper_.size());
  if (block_perm_.empty() || nb <= old || 4 * (nb - fully_ordered_blocks_) > fully_ordered_blocks_) {
    return false;
  }
  for (int j = 0; j < old; ++j) {
    if (upper_neighbours_[j] != ordered_upper_[j]) return false;
  }
  for (int j = old; j < nb; ++j) {
    for (int i : upper_neighbours_[j]) {
      if (i < old - 1) return false;  // linked to an older block than the newest: a loop
    }
  }
  return true;
}

bool BlockCholesky::order_blocks(std::vector<int>& block_perm) {
  const int nb = num_blocks_;
  std::size_t nnz = 0;
  for (const auto& rows : upper_neighbours_) nnz += rows.size() + 1;
  cholmod_sparse* B = cholmod_allocate_sparse(nb, nb, nnz, 1, 1, 1, CHOLMOD_PATTERN, &common_);
  if (!B) return false;
  auto* bp = static_cast<int*>(B->p);
  auto* bi = static_cast<int*>(B->i);
  int pos = 0;
  for (int j = 0; j < nb; ++j) {
    bp[j] = pos;
    for (int i : upper_neighbours_[j]) bi[pos++] = i;
    bi[pos++] = j;
  }
  bp[nb] = pos;
  block_perm.resize(nb);
  const int ok = ordering_ == Ordering::kBlockAmd
                     ? cholmod_amd(B, nullptr, 0, block_perm.data(), &common_)
                     : cholmod_metis(B, nullptr, 0, /*postorder=*/1, block_perm.data(), &common_);
  cholmod_free_sparse(&B, &common_);
  return ok;
}

bool BlockCholesky::analyse() {
  if (factor_) cholmod_free_factor(&factor_, &common_);
  if (ordering_ == Ordering::kScalarDefault) {
    factor_ = cholmod_analyze(matrix_, &common_);
  } else {
    // Order the graph of blocks (9 times fewer entries), then keep each block's 3 scalars
    // together; CHOLMOD postorders the given permutation and finds the supernodes.
    std::vector<int> block_perm;
    if (extends_last_ordering()) {
      block_perm = block_perm_;
      for (int j = static_cast<int>(block_perm_.size()); j < num_blocks_; ++j) {
        block_perm.push_back(j);
      }
      ++orderings_reused_;
    } else {
      if (!order_blocks(block_perm)) return false;
      fully_ordered_blocks_ = num_blocks_;
    }
    block_perm_ = block_perm;
    ordered_upper_ = upper_neighbours_;
    std::vector<int> perm(3 * static_cast<std::size_t>(num_blocks_));
    for (int r = 0; r < num_blocks_; ++r) {
      for (int u = 0; u < 3; ++u) perm[3 * r + u] = 3 * block_perm[r] + u;
    }
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_GIVEN;
    factor_ = cholmod_analyze_p(matrix_, perm.data(), nullptr, 0, &common_);
  }
  if (!factor_) return false;
  analysed_ = true;
  ++analyses_;
  return true;
}

bool BlockCholesky::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) {
  if (!factor_) return false;
  cholmod_dense b;
  b.nrow = b.d = rhs.size();
  b.ncol = 1;
  b.nzmax = rhs.size();
  b.x = const_cast<double*>(rhs.data());
  b.z = nullptr;
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* sol = cholmod_solve(CHOLMOD_A, factor_, &b, &common_);
  if (!sol) return false;
  x = Eigen::Map<const Eigen::VectorXd>(static_cast<double*>(sol->x), rhs.size());
  cholmod_free_dense(&sol, &common_);
  return x.allFinite();
}

Eigen::VectorXd BlockCholesky::multiply(const Eigen::VectorXd& v) const {
  Eigen::VectorXd y = Eigen::VectorXd::Zero(v.size());
  const auto* p = static_cast<const int*>(matrix_->p);
  const auto* ri = static_cast<const int*>(matrix_->i);
  const auto* x = static_cast<const double*>(matrix_->x);
  for (std::size_t c = 0; c < matrix_->ncol; ++c) {
    for (int k = p[c]; k < p[c + 1]; ++k) {
      const int r = ri[k];
      y[r] += x[k] * v[c];
      if (r != static_cast<int>(c)) y[c] += x[k] * v[r];
    }
  }
  return y;
}

Eigen::VectorXd BlockCholesky::diagonal() const {
  Eigen::VectorXd d(matrix_->ncol);
  const auto* p = static_cast<const int*>(matrix_->p);
  const auto* x = static_cast<const double*>(matrix_->x);
  for (std::size_t c = 0; c < matrix_->ncol; ++c) d[c] = x[p[c + 1] - 1];  // diagonal is last
  return d;
}

long BlockCholesky::nnz_h() const {
  return matrix_ ? static_cast<const int*>(matrix_->p)[matrix_->ncol] : 0;
}

long BlockCholesky::nnz_l() const {
  if (!factor_) return 0;
  if (factor_->is_super) {
    // Supernodal: count the lower trapezoid of every supernode.
    const auto* super = static_cast<const int*>(factor_->super);
    const auto* pi = static_cast<const int*>(factor_->pi);
    long nnz = 0;
    for (std::size_t s = 0; s < factor_->nsuper; ++s) {
      const long ncols = super[s + 1] - super[s], nrows = pi[s + 1] - pi[s];
      nnz += ncols * nrows - ncols * (ncols - 1) / 2;
    }
    return nnz;
  }
  const auto* nz = static_cast<const int*>(factor_->nz);
  long nnz = 0;
  for (std::size_t c = 0; c < factor_->n; ++c) nnz += nz[c];
  return nnz;
}

}  // namespace traverse::backend
