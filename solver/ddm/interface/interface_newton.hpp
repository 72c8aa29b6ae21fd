// Interface Newton: the contact problem solved on the interface (interface_problem.hpp) by one of the interface
// solvers (interface_solver.hpp: the sparse direct active set or the iterative FETI solver), then one solve per
// body for the fields.
//   exact:   find z >= 0 with g_free + F z >= 0, complementary;
//   penalty: the same with F + theta D (z = max(0, -g / theta) at every node), and with the augmented-Lagrangian
//            shift g_free - theta D lambda.
// The object keeps the interface problem, so augmented-Lagrangian updates (which only shift the gaps) cost one
// solve per body each.
#pragma once

#include "../method.hpp"
#include "interface_problem.hpp"
#include "interface_solver.hpp"

#include <memory>

namespace contact::ddm {

class InterfaceNewton {
 public:
  // The bodies' free responses are computed at load point `at` (the run's when the method first runs): later load
  // points scale them, or refresh them when a condition has its own history (interface_problem.hpp).
  InterfaceNewton(const ContactSystem& system, const SolverSettings& settings, parallel::TaskRunner& runner,
                  const fem::LoadPoint& at)
      : system_(system),
        settings_(resolved_settings(settings.interface, system)),
        kind_(choose_interface_solver(settings_, system, runner)),
        problem_(system, runner, interface_options(kind_, settings_, system.has_friction()), at),
        solver_(make_interface_solver(kind_, settings_, system.has_friction())) {}
  // Solves with the frame's enforcement at the run state's load point, slip origins and multipliers, building the
  // frame's outcome; reports every active-set step.
  void solve(RunFrame& frame);
  const InterfaceProblem& problem() const { return problem_; }
  const InterfaceSolver& solver() const { return *solver_; }

 private:
  // The error text for floating bodies that the active set leaves unheld (rows of G).
  std::string unheld_bodies(const std::vector<Eigen::Index>& rows) const;
  // Per body: its rigid-mode amplitudes (empty for a restrained body).
  std::vector<Eigen::VectorXd> rigid_amplitudes(const Eigen::VectorXd& alpha) const;

  // The problem as the solver takes it: H = F + theta D, g shifted by the multipliers, where each row lies.
  InterfaceQp make_qp(const SolverSettings& settings, const RunState& state) const;

  const ContactSystem& system_;
  InterfaceSolverSettings settings_;  // the job's, `auto` preconditioner resolved
  InterfaceSolverKind kind_;
  InterfaceProblem problem_;
  std::unique_ptr<InterfaceSolver> solver_;
  Eigen::VectorXd last_z_;      // warm start of the next solve: the last converged answer (load steps, updates, trials)
  Eigen::VectorXd last_alpha_;  // its floating bodies' rigid amplitudes
};

}  // namespace contact::ddm
