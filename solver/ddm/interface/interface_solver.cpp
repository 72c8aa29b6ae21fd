#include "interface_solver.hpp"

#include "feti.hpp"
#include "friction_direct.hpp"
#include "sparse_direct.hpp"

namespace contact::ddm {

namespace {

// Beyond these sizes the direct solver's costs outgrow the iterative one's (bench/bench_walls measures both):
// its Schur complement on the floating bodies' rows is dense (r x r, and |A| x r for H_AA^-1 G_A^T), and every
// active-set step refactorises the active block.
constexpr Eigen::Index max_direct_floating_rows = 256;
constexpr Eigen::Index max_direct_rows = 40000;
// Beyond this many floating-body rows (ten floating bodies) the `auto` preconditioner is none (resolved_settings).
constexpr Eigen::Index max_dirichlet_floating_rows = 30;

Eigen::Index floating_rows(const ContactSystem& system) {
  Eigen::Index rows = 0;
  for (size_t a = 0; a < system.n_bodies(); ++a) rows += system.body(a).rigid_modes().cols();
  return rows;
}

}  // namespace

InterfaceSolverSettings resolved_settings(const InterfaceSolverSettings& settings, const ContactSystem& system) {
  InterfaceSolverSettings out = settings;
  if (out.preconditioner == InterfacePreconditioner::automatic)
    out.preconditioner = floating_rows(system) > max_dirichlet_floating_rows ? InterfacePreconditioner::none
                                                                             : InterfacePreconditioner::dirichlet;
  return out;
}

InterfaceSolverKind choose_interface_solver(const InterfaceSolverSettings& settings, const ContactSystem& system,
                                            const parallel::TaskRunner& runner) {
  // By size only, not by the number of processes: the same job takes the same solver on any number of ranks, so
  // its answer does not depend on them (the direct solver runs replicated on every rank; docs/parallel.md).
  (void)runner;
  if (settings.solver != InterfaceSolverKind::automatic) return settings.solver;
  Eigen::Index rows = 0;
  for (const auto& pair : system.pairs()) rows += pair.n_rows();
  return floating_rows(system) > max_direct_floating_rows || rows > max_direct_rows ? InterfaceSolverKind::iterative
                                                                                    : InterfaceSolverKind::direct;
}

InterfaceProblem::Options interface_options(InterfaceSolverKind kind, const InterfaceSolverSettings& settings,
                                            bool friction) {
  InterfaceProblem::Options options;
  options.friction = friction;  // both solvers take the tangential rows
  if (kind == InterfaceSolverKind::iterative) {
    options.preconditioner = settings.preconditioner;
    options.replicate_blocks = false;  // each process applies its own bodies' blocks
  }
  return options;
}

std::unique_ptr<InterfaceSolver> make_interface_solver(InterfaceSolverKind kind,
                                                       const InterfaceSolverSettings& settings, bool friction) {
  if (kind == InterfaceSolverKind::iterative)
    return std::make_unique<FetiSolver>(settings);  // with or without friction
  if (friction) return std::make_unique<FrictionDirectSolver>();
  return std::make_unique<SparseDirectSolver>();
}

}  // namespace contact::ddm
