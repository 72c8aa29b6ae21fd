// MPRGP: modified proportioning with reduced gradient projections (Dostal & Schoeberl 2005; Dostal, "Optimal
// Quadratic Programming Algorithms", 2009, algorithm 5.8), for the bound-constrained QP
//
//   min f(x) = 1/2 x^T A x - b^T x   subject to   l <= x <= u,        A symmetric positive definite,
//
// given only products with A (and, optionally, a preconditioner); u is optional (+inf where absent, and l may be
// -inf: a free unknown; l = u fixes it). With the free set F = {i : l_i < x_i < u_i}, the gradient g = A x - b
// splits into the free gradient phi (g on F, 0 elsewhere) and the chopped gradient beta (min(g_i, 0) where x_i is
// at its lower bound, max(g_i, 0) at its upper bound: the part that points into the box, 0 for a fixed unknown):
// their sum, the projected gradient, vanishes exactly at the solution (Dostal 2009, section 5.8 for the box, the
// case of friction's tangential multipliers -b <= q <= b). Each iteration is one of three steps:
//   - conjugate gradients in the face F while x stays feasible and the chopped gradient is small against the
//     reduced free gradient (the iterate is "proportional": ||beta||^2 <= Gamma^2 phi~^T phi);
//   - an expansion step when the CG step would leave the feasible set: the longest feasible step along the CG
//     direction, then a projected gradient step of fixed length alpha_bar in (0, 2 / ||A||] (projected onto the
//     box), which adds constraints to the face several at a time;
//   - a proportioning step along beta when the chopped gradient dominates, which releases constraints.
// The rate of convergence depends on the spectrum of A only (Dostal's bound), so on a family of problems with a
// bounded condition number the iterations stay bounded: the property FETI relies on.
//
// Preconditioning in face: the CG directions use M phi restricted to F, with M an SPD approximation of A^-1
// (applied to the whole vector, then cut to the face); the expansion and proportioning steps are unchanged.
// Pure linear algebra: nothing here knows of contact.
#pragma once

#include "../common/solve_report.hpp"

#include <Eigen/Core>

#include <functional>

namespace contact::linalg {

struct BoundQp {
  // y = A x; returns true to stop (cancelled).
  std::function<bool(const Eigen::VectorXd& x, Eigen::VectorXd& y)> apply;
  // y = M r (an approximation of A^-1); empty: no preconditioner. Returns true to stop (cancelled).
  std::function<bool(const Eigen::VectorXd& r, Eigen::VectorXd& y)> precondition;
  Eigen::VectorXd b, lower;
  Eigen::VectorXd upper;  // empty: no upper bounds (+inf); entries may be +inf
  // Optional: the image L v, under a linear map L that `apply` computes on its way, of the vector last passed to
  // `apply` (SMALBE: the range part Q v, which its stopping test needs of every iterate). MPRGP then carries
  // L x along with x through its steps (MprgpResult::image: exact after a restart, updated like x in between, so
  // off by rounding only), and the stopping test costs no application of L of its own.
  std::function<const Eigen::VectorXd&()> image;
};

struct MprgpSettings {
  double alpha_bar = 0.0;  // the expansion step length: 1.9 / ||A|| is the usual choice (must be in (0, 2/||A||])
  double gamma = 1.0;      // the proportioning constant Gamma
  long max_iterations = 10000;
};

struct MprgpResult {
  Eigen::VectorXd x, gradient;  // the last iterate and its gradient A x - b
  Eigen::VectorXd image;        // L x when the problem gives `image`, else empty
  long cg_steps = 0, expansion_steps = 0, proportioning_steps = 0;
  // How it stopped: iterations are products with A, the measure is ||g^P(x)||; converged (done said so),
  // max_iterations or cancelled (a product asked to stop).
  SolveReport report;
  double projected_gradient() const { return report.measure; }
};

// Starts from x0 (projected onto the box) and stops when `done(state)` says so (converged), after max_iterations,
// or when a product asks to stop. `done` sees the current x, gradient, projected gradient's norm and image.
MprgpResult solve_mprgp(const BoundQp& qp, const Eigen::VectorXd& x0, const MprgpSettings& settings,
                        const std::function<bool(const MprgpResult& state)>& done);

// The projected gradient g^P of x (free gradient plus chopped gradient); `upper` empty: no upper bounds.
Eigen::VectorXd projected_gradient(const Eigen::VectorXd& x, const Eigen::VectorXd& g, const Eigen::VectorXd& lower,
                                   const Eigen::VectorXd& upper = Eigen::VectorXd());

// An estimate of ||A|| (the largest eigenvalue) by `iterations` steps of the power method from a fixed start.
double estimate_norm(const std::function<bool(const Eigen::VectorXd&, Eigen::VectorXd&)>& apply, Eigen::Index n,
                     int iterations = 30);

}  // namespace contact::linalg
