// Marginal covariances from a sparse Cholesky factor without forming the dense inverse.
//
// With P H P^T = L L^T, the entries of Sigma = H^-1 on the non-zero pattern of L are computed by
// the recursion of Takahashi, Fagan & Chen (1973), as used for SLAM covariance recovery by Kaess &
// Dellaert ("Covariance recovery from a square root information matrix for data association",
// RAS 2009): from Sigma L = L^-T, column by column from the last,
//   Sigma_ij = (delta_ij / L_jj - sum_{k > j, L_kj != 0} L_kj Sigma_ik) / L_jj,   i >= j,
// which only needs entries of Sigma on the pattern of L (the filled graph is chordal). The 3x3
// diagonal blocks of H are dense, so each block of Sigma lies on that pattern. Cost is about that
// of the numeric factorisation, memory one number per non-zero of L.
#pragma once

#include <cholmod.h>

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace traverse::backend {

// The 3x3 diagonal blocks of H^-1 (block b = rows/columns 3b..3b+2 of H in its original order),
// from a numeric factor of H in any CHOLMOD form (simplicial or supernodal, LL' or LDL'; the
// factor itself is not changed). Empty when the factor is missing or not positive definite.
std::optional<std::vector<Eigen::Matrix3d>> diagonal_blocks_of_inverse(const cholmod_factor* L,
                                                                       cholmod_common* common);

}  // namespace traverse::backend
