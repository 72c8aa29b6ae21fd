// The direct interface solver with friction: the semismooth Newton / primal-dual active set of Hueber, Stadler &
// Wohlmuth (linalg/friction_sets.hpp) on the interface problem with a tangential row per contact node of every
// friction pair (interface_problem.hpp, Options::friction). F is assembled once as a sparse matrix (the bodies'
// symmetric factorisations are used unchanged to build it); each step solves the square, non-symmetric system of
// the predicted stick and slip sets with the floating bodies' equilibrium,
//   [R F P   R G^T] [y    ]   [-R (g + F lambda0)]
//   [G P     0    ] [alpha] = [ e - G lambda0    ],
// by UMFPACK (sparse LU), until the sets repeat. The normal problem is first solved without friction (the
// frictionless direct solver's nested coarse start), then the friction problem on coarser multiplier spaces
// (linalg/friction_nested.hpp), which makes the first stick and slip sets nearly right. Floating bodies may be
// held by friction alone; a floating body whose loads pull it along its
// only contact harder than friction can hold is refused before the solve, naming the pair and the ratio.
#pragma once

#include "../../linalg/friction_sets.hpp"
#include "interface_solver.hpp"

namespace contact::ddm {

class FrictionDirectSolver final : public InterfaceSolver {
 public:
  const char* name() const override { return "direct"; }
  linalg::ActiveSetResult solve(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context) override;

 private:
  AssembledCompliance compliance_;
  Eigen::VectorXd last_alpha_;  // the floating bodies' rigid amplitudes of the last solve (with its warm start)
};

// The friction rows of the interface problem (one per contact node of each friction pair, paired with its normal
// row).
std::vector<linalg::FrictionRow> friction_rows(const InterfaceProblem& problem);

// Why friction cannot hold a floating body, if the loads already show it: the body's only contact is a friction
// pair and the loads' component along the pair's mean tangent exceeds what friction can carry (Coulomb: mu times
// the normal component; Tresca: the bound times the slave edge's covered length). Empty if none.
std::string friction_overload(const ContactSystem& system);

}  // namespace contact::ddm
