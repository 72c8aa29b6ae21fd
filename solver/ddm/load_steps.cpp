#include "load_steps.hpp"


namespace contact::ddm {

MethodOutcome run_load_steps(ContactSystem& system, const SolverSettings& settings, const std::vector<double>& factors,
                             RunContext& context, ContactMethod& method, StepLog& steps, int& updates) {
  MethodOutcome total;
  Displacements warm;
  updates = 0;
  for (size_t k = 0; k < factors.size(); ++k) {
    system.set_load_step(k, factors[k]);
    OffsetObserver observer(context.observer, total.iterations);
    RunContext inner{observer, context.cancel, context.runner, context.start, warm.empty() ? nullptr : &warm};
    int step_updates = 0;
    MethodOutcome o = run_enforced(system, settings, inner, method, step_updates);
    updates += step_updates;
    for (auto& r : o.history) {
      r.iteration += total.iterations;
      total.history.push_back(std::move(r));
    }
    total.iterations += o.iterations;
    total.add_work(o);
    total.gamma = o.gamma;
    total.reason = o.reason;
    total.converged = o.converged;
    const std::string prefix = factors.size() == 1 ? std::string()
                                                   : "load step " + std::to_string(k + 1) + " of " +
                                                         std::to_string(factors.size()) + ": ";
    if (o.u.empty()) {
      total.message = prefix + o.message;
      return total;
    }
    Step step = o.z.empty() ? system.fields(o.u, total.iterations)
                            : system.fields(o.u, o.z, total.iterations, &o.rigid_amplitudes, o.q.empty() ? nullptr : &o.q);
    step.index = static_cast<int>(k);
    step.load_factor = factors[k];
    steps.push_back(std::move(step));
    total.u = o.u;
    total.z = o.z;
    total.rigid_amplitudes = o.rigid_amplitudes;
    total.q = o.q;
    total.message = prefix + o.message;
    if (!o.converged) return total;
    system.accept_step(o.u);  // friction: the next step's slip is measured from here
    warm = std::move(o.u);
  }
  return total;
}

}  // namespace contact::ddm
