// The direct interface solver with friction: the semismooth Newton / primal-dual active set of Hueber, Stadler &
// Wohlmuth (linalg/friction_sets.hpp) on the interface problem with a tangential row per contact node of every
// friction pair (interface_problem.hpp, Options::friction). F is assembled once as a sparse matrix (the bodies'
// symmetric factorisations are used unchanged to build it); each step solves the square, non-symmetric system of
// the predicted stick and slip sets with the floating bodies' equilibrium,
//   [R F P   R G^T] [y    ]   [-R (g + F lambda0)]
//   [G P     0    ] [alpha] = [ e - G lambda0    ],
// by UMFPACK (sparse LU), until the sets repeat. The normal problem is first solved without friction (the
// frictionless direct solver's nested coarse start), then the friction problem on coarser multiplier spaces
// (linalg/friction_nested.hpp), which makes the first stick and slip sets nearly right; the Newton iteration is
// linalg/friction_newton.hpp (globalised: damped where the full steps stop making progress). Floating bodies may
// be held by friction alone; loads that statics shows friction cannot carry are refused before the solve
// (ddm/friction_statics.hpp).
#pragma once

#include "../../linalg/friction_sets.hpp"
#include "interface_solver.hpp"

namespace contact::ddm {

class FrictionDirectSolver final : public InterfaceSolver {
 public:
  const char* name() const override { return "direct"; }
  linalg::QpSolution solve(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context) override;

 private:
  AssembledCompliance compliance_;
};

}  // namespace contact::ddm
