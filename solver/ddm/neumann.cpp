// The paper's parallel Neumann domain decomposition, eqs. (16)-(17):
//   every body a solves  a_a(u~_a^{k+1}, v) = l_a(v) + (1/theta) int_S (d - u_1n^k - u_2n^k)^- v_an dS
//   independently (in parallel), then relaxes  u_a^{k+1} = gamma u~_a^{k+1} + (1 - gamma) u_a^k.
// Only the right-hand side changes between iterations, so each body's factorisation is reused throughout.
// The relaxation (fixed, auto, Anderson) lives in fixed_point.cpp, shared with the Robin variant.
#include "fixed_point.hpp"

namespace contact::ddm {

MethodOutcome run_neumann(const ContactSystem& system, const SolverSettings& settings, RunContext& context) {
  const size_t n = system.n_bodies();
  // Without contact pairs the bodies are independent: one solve each is the answer.
  if (system.pairs().empty()) {
    MethodOutcome out;
    std::vector<std::vector<char>> active;
    out.u = system.solve_bodies(Displacements(n), context.runner);
    out.iterations = 1;
    out.solves_per_body = 1;
    IterationReport r = system.report(1, out.u, active);
    r.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(r);
    out.history.push_back(std::move(r));
    out.converged = true;
    out.reason = StopReason::converged;
    out.message = "no contact pairs: each body solved once";
    return out;
  }
  int initial_solves = 0;
  Displacements u0 = initial_iterate(system, settings, context, initial_solves);
  NeumannMap map(system, context.runner);
  MethodOutcome out = run_fixed_point(system, settings, context, map, std::move(u0));
  out.solves_per_body += initial_solves;
  return out;
}

}  // namespace contact::ddm
