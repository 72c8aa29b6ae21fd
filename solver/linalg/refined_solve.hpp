// A sparse system solved by LU with iterative refinement, and judged by its residual. Both frictional saddle
// systems (the interface sets' system of the direct solver, friction_nested.cpp; the monolithic reference's KKT
// system, ddm/monolithic.cpp) mix the scales of stiffnesses, lengths and compliances, so an unsymmetric LU loses a
// few digits that a step or two of refinement recovers; and both must tell a singular system from a regular one
// where the factorisation does not (SparseLU factorises some singular matrices without a word and returns
// multipliers of 1e12, which sent the friction Newton cycling).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>

namespace contact::linalg {

// x = A^-1 b by the factorisation LU (Eigen::SparseLU, Eigen::UmfPackLU, ...) and `refinements` steps of iterative
// refinement. False when A cannot be factorised or x is not finite, and, with `strict`, when the refined residual
// ||A x - b|| is above 1e-8 ||b||: a system singular to rounding.
template <class LU>
bool refined_solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, int refinements, bool strict,
                   Eigen::VectorXd& x) {
  LU lu;
  lu.compute(A);
  if (lu.info() != Eigen::Success) return false;
  x = lu.solve(b);
  for (int k = 0; k < refinements; ++k) x += lu.solve(Eigen::VectorXd(b - A * x));
  if (!x.allFinite()) return false;
  return !strict || (A * x - b).norm() <= 1e-8 * std::max(b.norm(), 1e-300);
}

}  // namespace contact::linalg
