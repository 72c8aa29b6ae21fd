#include "gmres.hpp"

#include <cmath>
#include <vector>

namespace contact::bem {

namespace {

// Applies the Givens rotations of the previous columns to column k of the Hessenberg matrix and builds a new one
// that zeroes its subdiagonal entry; g holds the rotated right-hand side |r0| e_1.
void rotate_column(Eigen::MatrixXd& h, Eigen::VectorXd& cs, Eigen::VectorXd& sn, Eigen::VectorXd& g, int k) {
  for (int i = 0; i < k; ++i) {
    const double t = cs(i) * h(i, k) + sn(i) * h(i + 1, k);
    h(i + 1, k) = -sn(i) * h(i, k) + cs(i) * h(i + 1, k);
    h(i, k) = t;
  }
  const double r = std::hypot(h(k, k), h(k + 1, k));
  cs(k) = r > 0.0 ? h(k, k) / r : 1.0;
  sn(k) = r > 0.0 ? h(k + 1, k) / r : 0.0;
  h(k, k) = r;
  h(k + 1, k) = 0.0;
  g(k + 1) = -sn(k) * g(k);
  g(k) = cs(k) * g(k);
}

}  // namespace

SolveReport gmres(const LinearOperator& A, const LinearOperator& M, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                  const GmresOptions& options) {
  SolveReport result;
  const Eigen::Index n = b.size();
  const double b_norm = b.norm();
  if (x.size() != n) x = Eigen::VectorXd::Zero(n);
  if (b_norm == 0.0) {
    x.setZero();
    result.stop = SolveStop::converged;
    return result;
  }
  const int m = options.restart;
  Eigen::VectorXd r(n), w(n), z(n);
  std::vector<Eigen::VectorXd> basis(static_cast<std::size_t>(m) + 1);
  while (result.iterations < options.max_iterations) {
    // Phase 1: the residual of the current x starts a Krylov basis.
    A(x, w);
    r = b - w;
    double beta = r.norm();
    result.measure = beta / b_norm;
    if (result.measure <= options.relative_tolerance) {
      result.stop = SolveStop::converged;
      return result;
    }
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(m + 1, m);
    Eigen::VectorXd cs = Eigen::VectorXd::Zero(m), sn = Eigen::VectorXd::Zero(m), g = Eigen::VectorXd::Zero(m + 1);
    g(0) = beta;
    basis[0] = r / beta;
    // Phase 2: Arnoldi with modified Gram-Schmidt on A M, Givens rotations keep the least-squares residual |g(k+1)|.
    int k = 0;
    for (; k < m && result.iterations < options.max_iterations; ++k) {
      if (options.cancelled && options.cancelled()) {
        result.stop = SolveStop::cancelled;
        break;
      }
      M(basis[static_cast<std::size_t>(k)], z);
      A(z, w);
      ++result.iterations;
      for (int i = 0; i <= k; ++i) {
        h(i, k) = w.dot(basis[static_cast<std::size_t>(i)]);
        w -= h(i, k) * basis[static_cast<std::size_t>(i)];
      }
      const double next_norm = w.norm();  // h(k + 1, k) before the rotation zeroes it
      h(k + 1, k) = next_norm;
      if (next_norm > 0.0) basis[static_cast<std::size_t>(k) + 1] = w / next_norm;
      rotate_column(h, cs, sn, g, k);
      result.measure = std::abs(g(k + 1)) / b_norm;
      if (result.measure <= options.relative_tolerance || next_norm == 0.0) {  // converged, or breakdown
        ++k;
        break;
      }
    }
    // Phase 3: x += M V_k y_k with H_k y_k = g_k (upper triangular after the rotations).
    if (k > 0) {
      const Eigen::VectorXd y = h.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
      Eigen::VectorXd update = Eigen::VectorXd::Zero(n);
      for (int i = 0; i < k; ++i) update += y(i) * basis[static_cast<std::size_t>(i)];
      M(update, z);
      x += z;
    }
    if (result.cancelled()) return result;
    if (result.measure <= options.relative_tolerance) {
      // Confirm with the true residual (the rotated one can drift slightly).
      A(x, w);
      result.measure = (b - w).norm() / b_norm;
      if (result.measure <= 10.0 * options.relative_tolerance) {
        result.stop = SolveStop::converged;
        return result;
      }
    }
  }
  return result;
}

}  // namespace contact::bem
