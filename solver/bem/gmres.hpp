// Restarted GMRES with right preconditioning (Saad, "Iterative Methods for Sparse Linear Systems", 2nd ed.,
// algorithm 9.5): the residual it monitors is the true residual |b - A x|, not a preconditioned one.
#pragma once

#include <Eigen/Core>
#include <functional>

#include "../common/solve_report.hpp"

namespace contact::bem {

// y = A x (y pre-sized by the caller).
using LinearOperator = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd& y)>;

struct GmresOptions {
  double relative_tolerance = 1e-10;  // stop at |b - A x| <= relative_tolerance |b|
  int restart = 60;                   // Krylov dimension before a restart
  int max_iterations = 2000;          // matrix products in all
  std::function<bool()> cancelled;    // checked before every product; true stops at once
};

// Solves A x = b from the initial guess in x, with the preconditioner M ~ A^-1 applied as x = M (M y). The report's
// iterations are products with A, its measure the relative residual |b - A x| / |b|; it stops converged,
// max_iterations or cancelled.
SolveReport gmres(const LinearOperator& A, const LinearOperator& M, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                  const GmresOptions& options);

}  // namespace contact::bem
