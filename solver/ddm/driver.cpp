#include "driver.hpp"

#include "augmented_lagrangian.hpp"

#include <sstream>

namespace contact::ddm {

void OffsetObserver::on_iteration(const IterationReport& r) {
  IterationReport copy = r;
  copy.iteration += offset_;
  if (update_ > 0) copy.update = update_;
  if (!refined_.empty()) {
    for (size_t a = 0; a < copy.bodies.size() && a < refined_.size(); ++a) copy.bodies[a].elements_refined = refined_[a];
    refined_.clear();
  }
  inner_.on_iteration(copy);
}

MethodOutcome run_enforced(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                           ContactMethod& method, int& updates) {
  updates = 0;
  if (settings.enforcement == Enforcement::exact &&
      (settings.method == Method::neumann || settings.method == Method::robin)) {
    MethodOutcome out;
    out.reason = StopReason::error;
    out.message = std::string("method ") + (settings.method == Method::neumann ? "neumann" : "robin") +
                  " iterates on the penalty problem: enforcement exact is not available with it (use penalty, or "
                  "augmented_lagrangian for exact contact in the limit; or method interface_newton)";
    return out;
  }
  if (settings.enforcement == Enforcement::augmented_lagrangian)
    return run_augmented_lagrangian(system, settings, context, method, updates);
  return method.run(context);
}

}  // namespace contact::ddm
