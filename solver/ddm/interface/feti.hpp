// The iterative interface solver, FETI-style (Dostal's TFETI for contact; PERMON's SMALXE + MPGP are the
// reference implementation): the dual problem in the nodal pressures,
//
//   min 1/2 z^T H z + g^T z   over z >= 0 with G z = e          (H = F + diag(penalty), interface_solver.hpp)
//   (with friction: over the box of the normal and tangential multipliers, below)
//
// 1. Homogenise the equalities: z = z_hat + z_I with z_I = G^T (G G^T)^-1 e (coarse_space.hpp), so G z_hat = 0
//    and the bounds become z_hat >= -z_I.
// 2. In ker G replace H by P H P (equal there) and add rho Q: the Hessian A = P H P + rho Q has the spectrum of H
//    on ker G, bounded by the bodies' size over the mesh size and not by their number, plus rho on the rigid
//    motions' gaps; the linear term is P (g + H z_I).
// 3. SMALBE (semi-monotonic augmented Lagrangian for bound and equality constraints, Dostal 2006): outer
//    updates of the equality multipliers nu (kept as G~^T mu, a vector in range G^T) nu += rho Q z_hat, each
//    after an inner MPRGP solve (linalg/mprgp.hpp) of the bound-constrained problem to a precision tied to the
//    remaining equality violation, min(M ||Q z_hat||, eta); M is halved when the Lagrangian does not grow enough.
// 4. The floating bodies' rigid amplitudes at the end: alpha = least squares of G_A^T alpha = -(g + H z)_A on the
//    active nodes A.
// Preconditioner in face (MPRGP's CG steps): P M P + Q / rho with M = (D^-2/2) sum_a B_a X_a B_a^T (D^-2/2),
// X_a the body's Schur complement on its contact unknowns (Dirichlet) or its stiffness there (lumped).
// Each product with A is one product with F, which every process computes for its own bodies and one
// MPI_Allreduce sums; P and Q cost one solve with the sparse G G^T, replicated. Stops when the projected gradient
// and the equality violation are both below the tolerance relative to the problem's own scales.
// The engine (SMALBE, MPRGP's calls, the rigid amplitudes) is smalbe.hpp.
//
// Friction (interface problem built with tangential rows, interface_options(..., friction = true)): the unknowns
// are [z; q], the box z >= 0, -b <= q <= b (MPRGP with upper bounds), shifted by -z_I like the normal bounds.
// Tresca (b = g) is one solve; Coulomb (b = mu z) an outer fixed point on b, each step a Tresca solve from the last
// answer (feti_friction.cpp). Rows no body can move tangentially are fixed at q = 0, as friction_direct does. The
// answer is the direct friction solver's discrete solution (same layout: normal rows, then tangential ones).
#pragma once

#include "interface_solver.hpp"

namespace contact::ddm {

class FetiSolver final : public InterfaceSolver {
 public:
  explicit FetiSolver(const InterfaceSolverSettings& settings) : settings_(settings) {}
  const char* name() const override { return "iterative"; }
  linalg::QpSolution solve(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context) override;

 private:
  linalg::QpSolution solve_friction(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context);
  InterfaceSolverSettings settings_;
};

}  // namespace contact::ddm
