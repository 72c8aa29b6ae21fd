#include "aca.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <vector>

namespace contact::bem {

namespace {

// The next row to try: the unused one where the last column is largest in magnitude, or any unused row.
int next_pivot_row(const Eigen::VectorXd& last_column, const std::vector<bool>& used) {
  int best = -1;
  double largest = -1.0;
  for (Eigen::Index i = 0; i < last_column.size(); ++i) {
    if (used[static_cast<std::size_t>(i)]) continue;
    if (std::abs(last_column(i)) > largest) {
      largest = std::abs(last_column(i));
      best = static_cast<int>(i);
    }
  }
  return best;
}

// The residual row i of the block after the crosses so far.
void residual_row(const BlockRow& row, const std::vector<Eigen::VectorXd>& us, const std::vector<Eigen::VectorXd>& vs,
                  int i, Eigen::VectorXd& r) {
  row(i, r);
  for (std::size_t k = 0; k < us.size(); ++k) r -= us[k](i) * vs[k];
}

// Partial pivoting only looks where the crosses lead, and misses parts of a block that do not couple to them
// (for straight boundaries, the x and y equations of the elasticity kernels decouple in places). Before accepting,
// the residual is checked on sample rows spread over the block, both components: returns a row whose residual is
// above the tolerance (scaled to the block), or -1.
int unconverged_sample_row(const BlockRow& row, const std::vector<Eigen::VectorXd>& us,
                           const std::vector<Eigen::VectorXd>& vs, const std::vector<bool>& used, int rows, int columns,
                           double tolerance, double norm2) {
  constexpr int kSamplePairs = 4;
  Eigen::VectorXd r(columns);
  for (int s = 0; s < kSamplePairs; ++s)
    for (int offset = 0; offset < 2; ++offset) {
      const int i = std::min(rows - 1, s * rows / kSamplePairs + offset);
      if (used[static_cast<std::size_t>(i)]) continue;
      residual_row(row, us, vs, i, r);
      if (r.squaredNorm() * rows > tolerance * tolerance * norm2) return i;
    }
  return -1;
}

}  // namespace

LowRank adaptive_cross_approximation(int rows, int columns, const BlockRow& row, const BlockColumn& column,
                                     double tolerance, int max_rank) {
  std::vector<Eigen::VectorXd> us, vs;
  std::vector<bool> used(static_cast<std::size_t>(rows), false);
  Eigen::VectorXd r(columns), c = Eigen::VectorXd::Zero(rows);
  double norm2 = 0.0;  // |U V^T|_F^2 of the crosses so far
  int pivot = 0, zero_rows = 0;
  while (static_cast<int>(us.size()) < max_rank && pivot >= 0) {
    // Phase 1: the residual row at the pivot and its largest entry.
    used[static_cast<std::size_t>(pivot)] = true;
    residual_row(row, us, vs, pivot, r);
    Eigen::Index j = 0;
    const double largest = r.cwiseAbs().maxCoeff(&j);
    if (!(largest > 1e-14 * std::sqrt(norm2)) || largest == 0.0) {
      // Nothing left in this row: try another (a few, then check the samples).
      if (++zero_rows > 8 || static_cast<int>(us.size()) + zero_rows >= rows) {
        pivot = unconverged_sample_row(row, us, vs, used, rows, columns, tolerance, norm2);
        zero_rows = 0;
        continue;
      }
      c.setZero();
      pivot = next_pivot_row(c, used);
      continue;
    }
    // Phase 2: the residual column through the pivot entry.
    const Eigen::VectorXd v = r / r(j);
    column(static_cast<int>(j), c);
    for (std::size_t k = 0; k < us.size(); ++k) c -= vs[k](j) * us[k];
    // Phase 3: the norm update |S_k|^2 = |S_{k-1}|^2 + 2 sum_l (u.u_l)(v.v_l) + |u|^2 |v|^2, and the stop test,
    // confirmed on sample rows.
    const double uu = c.squaredNorm(), vv = v.squaredNorm();
    for (std::size_t k = 0; k < us.size(); ++k) norm2 += 2.0 * c.dot(us[k]) * v.dot(vs[k]);
    norm2 += uu * vv;
    us.push_back(c);
    vs.push_back(v);
    pivot = std::sqrt(uu * vv) <= tolerance * std::sqrt(norm2)
                ? unconverged_sample_row(row, us, vs, used, rows, columns, tolerance, norm2)
                : next_pivot_row(c, used);
  }
  LowRank out;
  out.U.resize(rows, static_cast<Eigen::Index>(us.size()));
  out.V.resize(columns, static_cast<Eigen::Index>(vs.size()));
  for (std::size_t k = 0; k < us.size(); ++k) {
    out.U.col(static_cast<Eigen::Index>(k)) = us[k];
    out.V.col(static_cast<Eigen::Index>(k)) = vs[k];
  }
  return out;
}

void recompress(LowRank& block, double tolerance) {
  const Eigen::Index k = block.U.cols();
  if (k <= 1 || k > block.U.rows() || k > block.V.rows()) return;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qu(block.U), qv(block.V);
  const Eigen::MatrixXd ru = qu.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd rv = qv.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(ru * rv.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  // Keep the smallest rank whose discarded tail is below tolerance |S|_F.
  const double limit2 = tolerance * tolerance * s.squaredNorm();
  Eigen::Index rank = k;
  double tail2 = 0.0;
  while (rank > 0 && tail2 + s(rank - 1) * s(rank - 1) <= limit2) {
    tail2 += s(rank - 1) * s(rank - 1);
    --rank;
  }
  const Eigen::MatrixXd qu_thin = qu.householderQ() * Eigen::MatrixXd::Identity(block.U.rows(), k);
  const Eigen::MatrixXd qv_thin = qv.householderQ() * Eigen::MatrixXd::Identity(block.V.rows(), k);
  block.U = qu_thin * (svd.matrixU().leftCols(rank) * s.head(rank).asDiagonal());
  block.V = qv_thin * svd.matrixV().leftCols(rank);
}

}  // namespace contact::bem
