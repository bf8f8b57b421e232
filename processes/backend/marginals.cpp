#include "marginals.hpp"

namespace traverse::backend {
namespace {

// Sigma on the pattern of a simplicial, packed LL' factor; same layout as L->x.
std::vector<double> takahashi(const cholmod_factor* L) {
  const int n = static_cast<int>(L->n);
  const auto* Lp = static_cast<const int*>(L->p);
  const auto* Li = static_cast<const int*>(L->i);
  const auto* Lx = static_cast<const double*>(L->x);
  std::vector<double> S(Lp[n], 0.0);
  std::vector<int> pos(n, -1);  // row -> entry of the current column, -1 if absent
  std::vector<double> acc;
  for (int j = n - 1; j >= 0; --j) {
    const int p0 = Lp[j], p1 = Lp[j + 1];  // Li[p0] == j: the diagonal comes first
    const double Ljj = Lx[p0];
    for (int q = p0 + 1; q < p1; ++q) pos[Li[q]] = q;
    acc.assign(p1 - p0, 0.0);
    // acc(i) = sum_{k in struct(j)} Sigma_ik L_kj for every i in struct(j); each pair (i, k) with
    // i >= k is stored in column k of Sigma (already final since k > j).
    for (int qk = p0 + 1; qk < p1; ++qk) {
      const int k = Li[qk];
      const double Lkj = Lx[qk];
      for (int q = Lp[k]; q < Lp[k + 1]; ++q) {
        const int i = Li[q];
        const int qi = pos[i];
        if (qi < 0) continue;
        acc[qi - p0] += S[q] * Lkj;
        if (i != k) acc[qk - p0] += S[q] * Lx[qi];
      }
    }
    double diag = 1.0 / Ljj;
    for (int q = p0 + 1; q < p1; ++q) {
      S[q] = -acc[q - p0] / Ljj;
      diag -= Lx[q] * S[q];
      pos[Li[q]] = -1;
    }
    S[p0] = diag / Ljj;
  }
  return S;
}

// Sigma(r, c) in the permuted order, from column min(r, c).
double lookup(const cholmod_factor* L, const std::vector<double>& S, int r, int c) {
  if (r < c) std::swap(r, c);
  const auto* Lp = static_cast<const int*>(L->p);
  const auto* Li = static_cast<const int*>(L->i);
  for (int q = Lp[c]; q < Lp[c + 1]; ++q) {
    if (Li[q] == r) return S[q];
  }
  return 0.0;  // not reached for entries of dense diagonal blocks
}

}  // namespace

std::optional<std::vector<Eigen::Matrix3d>> diagonal_blocks_of_inverse(const cholmod_factor* L,
                                                                       cholmod_common* common) {
  if (!L || L->minor < L->n || L->xtype != CHOLMOD_REAL) return std::nullopt;
  cholmod_factor* F = cholmod_copy_factor(const_cast<cholmod_factor*>(L), common);
  if (!F) return std::nullopt;
  // Simplicial, packed, monotonic LL': column j is Lp[j]..Lp[j+1], diagonal first.
  if (!cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/0, /*to_packed=*/1,
                             /*to_monotonic=*/1, F, common)) {
    cholmod_free_factor(&F, common);
    return std::nullopt;
  }
  const std::vector<double> S = takahashi(F);
  const int n = static_cast<int>(F->n);
  const auto* perm = static_cast<const int*>(F->Perm);
  std::vector<int> inverse_perm(n);
  for (int r = 0; r < n; ++r) inverse_perm[perm ? perm[r] : r] = r;
  std::vector<Eigen::Matrix3d> blocks(n / 3);
  for (int b = 0; b < n / 3; ++b) {
    for (int u = 0; u < 3; ++u) {
      for (int w = u; w < 3; ++w) {
        blocks[b](u, w) = blocks[b](w, u) =
            lookup(F, S, inverse_perm[3 * b + u], inverse_perm[3 * b + w]);
      }
    }
  }
  cholmod_free_factor(&F, common);
  return blocks;
}

}  // namespace traverse::backend
