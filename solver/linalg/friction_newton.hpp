// The semismooth Newton of frictional contact (Hueber, Stadler & Wohlmuth's primal-dual active set on the stick and
// slip sets, friction_sets.hpp), globalised. The direct frictional solvers run it: the direct interface solver
// (ddm/interface/friction_direct), its coarse levels (friction_nested) and the monolithic reference (ddm/monolithic);
// each gives only the linear system of a set (`FrictionNewtonProblem::solve`). The iterative interface solver with
// friction (ddm/interface/feti_friction) does not: it solves the friction box by SMALBE + MPRGP, Coulomb by an outer
// iteration on the slip bounds, and of linalg's friction code uses only friction_sets.hpp (the rows, the sets'
// prediction, the complementarity).
//
// Why a globalisation: the full-step iteration is exact once the sets are right and usually gets there in a few
// steps, but from a poor start on many bodies it can cycle (the sets of two or more steps repeating) or run into
// sets whose system is singular (a floating body whose every contact node slips the same way, or opens). The
// iteration here keeps the full steps while they make progress and otherwise
//   * damps: the complementarity function C (friction_sets.hpp) is piecewise affine, and the Newton point of the
//     sets predicted at x solves C's affine piece there, so d = x_N - x is a descent direction of the merit
//     Theta = ||C||^2 (Theta(x + t d) = (1 - t)^2 Theta(x) for small t); a backtracking line search on Theta
//     (Armijo) gives a monotone decrease, which cannot cycle;
//   * the full step is taken without a line search while the sets are new and Theta has reached a new low within
//     the last four steps (a watchdog: the usual run, whose Theta may rise for a step before it falls to zero, is
//     unchanged); a repeated set (a cycle) or four steps without progress switch to the line search;
//   * where another solver can take the step over (the direct interface solver's, ddm/friction_policy.hpp), it
//     stops once it stalls: the lowest merit of its last few accepted steps not even halved against the lowest
//     before them (cycling or crawling by damped steps, which settle, if ever, only after tens of linear solves);
//   * a singular system is met by moving towards the predicted sets in halves: the rows whose state would change
//     are ordered by how far their prediction lies past the switching point, and only the first half (a quarter,
//     ...) switches, until the system is solvable; if not even one switch is, the solver says so (`singular`).
// Pure linear algebra.
#pragma once

#include "../common/solve_report.hpp"

#include <functional>

#include "active_set.hpp"
#include "friction_sets.hpp"

namespace contact::linalg {

// An iterate: the multipliers, their conjugates h (gaps and slips) and the other unknowns solved with them (the
// floating bodies' rigid amplitudes; the monolithic solver's displacements). On a set's system all three are
// affine in the free multipliers, so a damped step moves them along one line and h stays exact.
struct FrictionIterate {
  Eigen::VectorXd lambda, h, other;
};

// A level's problem: its friction rows and scaling c (friction_scaling), and the solve of the square system of a
// set's parametrisation; false when it is singular.
struct FrictionNewtonProblem {
  const std::vector<FrictionRow>& rows;
  const std::vector<char>& mask;  // tangential unknowns (tangential_mask)
  const Eigen::VectorXd& c;
  std::function<bool(const FrictionParametrization& p, FrictionIterate& out)> solve;
  // Polled before every linear solve (the halvings included); true stops the iteration (`stopped`). Optional.
  std::function<bool()> cancelled = {};
};

struct FrictionNewtonSettings {
  int max_steps = 100;
  double tolerance = 1e-13;  // friction_complementarity at which an iterate is taken as the solution
  // Stalled: the lowest merit of the last `stall_steps` accepted steps fell by less than `stall_fall` of the lowest
  // before them (the iteration cycles or crawls by damped steps); it stops then as `max_iterations` with `stalled`
  // set. 0: never (the monolithic reference and the coarse levels, which have no solver to hand over to).
  int stall_steps = 0;
  double stall_fall = 0.5;
};

struct FrictionNewtonResult {
  FrictionIterate iterate;  // the last (for singular: the last solvable one; empty if none was)
  FrictionSets sets;        // the sets of the last solve
  FrictionSets unsolvable;  // singular: the predicted sets whose system (and every one towards them) was singular
  int damped_steps = 0;     // steps the line search shortened
  int accepted_steps = 0;   // iterates accepted (each after one or more linear solves)
  bool stalled = false;     // stopped by the stall rule (FrictionNewtonSettings::stall_steps)
  // iterations: linear systems solved (each step's, the halvings included). converged: the sets repeated (the
  // iterate is the exact solution of its sets) or the complementarity vanished; singular: no set on the way to the
  // predicted one had a solvable system; max_iterations: not settled within max_steps, or stalled; cancelled: the
  // step callback asked to stop.
  SolveReport report;
};

// After every accepted step: the iterate and the step's counts; true stops.
using FrictionStepCallback = std::function<bool(const FrictionIterate& x, const ActiveSetStep& step)>;

FrictionNewtonResult friction_newton(const FrictionNewtonProblem& problem, FrictionSets start,
                                     const FrictionNewtonSettings& settings, const FrictionStepCallback& on_step = {});

// The merit Theta = ||C||^2 of the line search: C as the Newton step linearises it (the normal part as in
// friction_complementarity, the tangential one with the bound of the normal trial mu max(0, z - c h_n), which is
// what the slip rows of a set impose).
double friction_merit(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                      const std::vector<FrictionRow>& rows, const std::vector<char>& mask);

}  // namespace contact::linalg
