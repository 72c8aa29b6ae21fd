// The solvers of the interface problem (interface_problem.hpp) behind one interface: find the nodal pressures z
// and the floating bodies' rigid amplitudes alpha with
//
//   h = g + H z + G^T alpha >= 0,  z >= 0,  z h = 0,  G z = e,     H = F + diag(penalty),
//
// the KKT system of  min 1/2 z^T H z + g^T z  over z >= 0 with G z = e. Two solvers give the same discrete
// solution (to the iterative one's tolerance):
//   direct    (sparse_direct.hpp): the primal-dual active set on F assembled as a sparse matrix, CHOLMOD at every
//             step; first active set from nested coarse solves. Exact in finitely many steps; one process holds
//             every block.
//   friction  (friction_direct.hpp): the direct solver's setting with friction pairs: semismooth Newton on the
//             stick and slip sets of the normal and tangential multipliers.
//   iterative (feti.hpp): FETI-style projected MPRGP inside SMALBE, applying F block by block where the blocks
//             live (MPI ranks: each its own bodies), with the coarse space of the floating bodies; with friction
//             MPRGP on the box z >= 0, |q| <= b (Tresca; Coulomb by an outer iteration on b = mu z).
// make_interface_solver picks one from the settings and the size of the problem; a new solver is a new class here.
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"
#include "../run_frame.hpp"
#include "interface_problem.hpp"

#include <memory>
#include <string>

namespace contact::ddm {

struct InterfaceQp {
  const InterfaceProblem& problem;
  Eigen::VectorXd penalty;  // theta D per row (zeros: exact contact)
  Eigen::VectorXd g;        // weighted gaps at z = 0 (shifted by the augmented Lagrangian's multipliers)
  Equalities equilibrium;   // the floating bodies' G z = e
  // Where each row lies (its pair and its arc length along the slave edge): the direct solver's coarse guesses.
  std::vector<int> line;
  Eigen::VectorXd position;
};

// What an interface solver receives: the run's frame (its runner and its stop check) and the interface Newton's
// report of each step.
struct InterfaceSolveContext {
  RunFrame& frame;
  const linalg::StepCallback& on_step;  // after every active-set step / outer iteration (reports); true stops
  int max_steps = 100;                  // active-set steps / outer iterations
  // The direct friction Newton stops once it stalls over this many steps (0: never; set where another solver
  // takes the step over, ddm/friction_policy.hpp's chain).
  int stall_steps = 0;
  // The floating bodies' rigid amplitudes of the answer the warm start z0 is (empty: none), whichever solver gave it.
  Eigen::VectorXd alpha0;
  std::string note;  // out: what the first report says (coarse solves, solver chosen)
};

// F assembled as a sparse matrix once per interface problem, for the direct solvers (augmented-Lagrangian updates
// and load steps change only the gaps and the penalty diagonal).
class AssembledCompliance {
 public:
  const SparseMatrix& of(const InterfaceProblem& problem) {
    if (for_ != &problem) {
      F_ = problem.assemble();
      for_ = &problem;
    }
    return F_;
  }

 private:
  const InterfaceProblem* for_ = nullptr;
  SparseMatrix F_;
};

class InterfaceSolver {
 public:
  virtual ~InterfaceSolver() = default;
  virtual const char* name() const = 0;  // "direct" or "iterative": the job's and the result's word
  // z0: the warm start (the previous load step's or update's pressures), or null.
  virtual linalg::QpSolution solve(const InterfaceQp& qp, const Eigen::VectorXd* z0,
                                   InterfaceSolveContext& context) = 0;
};

// The solver to use for `system` under `settings`: the one asked for, or, automatically, the iterative solver
// where the direct one's dense Schur complement on the floating bodies' rows (r x r) or its sparse factor would be
// large, the direct one otherwise (by size alone: the same on any number of processes; with or without friction).
InterfaceSolverKind choose_interface_solver(const InterfaceSolverSettings& settings, const ContactSystem& system,
                                            const parallel::TaskRunner& runner);
// The settings with the preconditioner `auto` resolved, by size alone (the same on any number of processes): with
// more than 30 floating-body rows (ten floating bodies) none, else dirichlet. Why: on walls of floating bricks the
// coarse space carries the global coupling, Dirichlet cuts the MPRGP iterations by 5-35 % only (on dowelled
// frictionless walls it adds to them), and each iteration costs a second dense product per body: none is as fast
// or faster from 19 bodies up (1.15-1.8x on 16 x 16 frictional walls of 4 to 16 cells per brick; 106 s against
// 150 s at 64 x 64). On two or three finely meshed bodies it cuts them 1.6-2.6x (docs/friction-solvers.md).
InterfaceSolverSettings resolved_settings(const InterfaceSolverSettings& settings, const ContactSystem& system);
// How the interface problem must be built for that solver (blocks replicated or not, preconditioner, tangential
// rows for friction).
InterfaceProblem::Options interface_options(InterfaceSolverKind kind, const InterfaceSolverSettings& settings,
                                            bool friction = false);
// With friction: direct is the semismooth Newton on stick and slip sets (friction_direct.hpp), iterative FETI on
// the box of the normal and tangential multipliers (feti.hpp).
std::unique_ptr<InterfaceSolver> make_interface_solver(InterfaceSolverKind kind,
                                                       const InterfaceSolverSettings& settings, bool friction = false);

}  // namespace contact::ddm
