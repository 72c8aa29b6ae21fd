// Adaptive cross approximation (ACA) with partial pivoting, and recompression, for the admissible blocks of the
// hierarchical BEM (docs/bem.md, "Hierarchical BEM"). Bebendorf, "Hierarchical Matrices" (2008), section 3.4.
#pragma once

#include <Eigen/Core>
#include <functional>

namespace contact::bem {

// A block approximated as U V^T (U: rows x k, V: columns x k).
struct LowRank {
  Eigen::MatrixXd U, V;
  int rank() const { return static_cast<int>(U.cols()); }
};

// Fills `out` (pre-sized) with row i, or column j, of the exact block.
using BlockRow = std::function<void(int i, Eigen::Ref<Eigen::VectorXd> out)>;
using BlockColumn = std::function<void(int j, Eigen::Ref<Eigen::VectorXd> out)>;

// ACA with partial pivoting: cross k takes the residual's row i_k, its largest entry j_k, the residual's column
// j_k, and the next row where that column is largest. Stops when |u_k| |v_k| <= tolerance |U V^T|_F (the norm
// updated exactly), or at max_rank (the caller then evaluates the block densely). Rows whose residual vanishes are
// skipped. Returns an empty LowRank (rank 0) for a block that is zero to round-off.
LowRank adaptive_cross_approximation(int rows, int columns, const BlockRow& row, const BlockColumn& column,
                                     double tolerance, int max_rank);

// Recompression: U = Q_u R_u, V = Q_v R_v, R_u R_v^T = W S Z^T (SVD); keeps the singular values whose discarded
// tail has Frobenius norm <= tolerance |S|. The result has the smallest rank for that relative error.
void recompress(LowRank& block, double tolerance);

}  // namespace contact::bem
