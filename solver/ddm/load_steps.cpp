#include "load_steps.hpp"


namespace contact::ddm {

MethodOutcome run_load_steps(ContactSystem& system, const SolverSettings& settings, const std::vector<double>& factors,
                             RunContext& context, ContactMethod& method, StepLog& steps) {
  OutcomeAccumulator steps_so_far;
  MethodOutcome& total = steps_so_far.total();
  Displacements warm;
  for (size_t k = 0; k < factors.size(); ++k) {
    system.set_load_step(k, factors[k]);
    steps_so_far.run(context, warm.empty() ? nullptr : &warm, InnerMarks{},
                     [&](RunContext& inner) { return run_enforced(system, settings, inner, method); });
    const std::string prefix = factors.size() == 1 ? std::string()
                                                   : "load step " + std::to_string(k + 1) + " of " +
                                                         std::to_string(factors.size()) + ": ";
    total.message = prefix + total.message;
    if (total.u.empty()) return steps_so_far.take();
    Step step = total.z.empty() ? system.fields(total.u, total.iterations)
                                : system.fields(total.u, total.z, total.iterations, &total.rigid_amplitudes,
                                                total.q.empty() ? nullptr : &total.q);
    step.index = static_cast<int>(k);
    step.load_factor = factors[k];
    step.converged = total.converged;
    steps.push_back(std::move(step));
    if (!total.converged) return steps_so_far.take();
    system.accept_step(total.u);  // friction: the next step's slip is measured from here
    warm = total.u;
  }
  return steps_so_far.take();
}

}  // namespace contact::ddm
