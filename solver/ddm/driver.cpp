#include "driver.hpp"

#include "augmented_lagrangian.hpp"

#include <sstream>
#include <string>
#include <utility>

namespace contact::ddm {

MethodOutcome run_enforced(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                           ContactMethod& method) {
  // The job reader reports this for a job; a Problem built in code meets it here, in the same words.
  if (std::string conflict = settings_conflict(settings); !conflict.empty()) {
    MethodOutcome out;
    out.reason = StopReason::error;
    out.refused = true;  // a setting, not the loads: no increment is solved
    out.message = std::move(conflict);
    return out;
  }
  if (settings.enforcement == Enforcement::augmented_lagrangian)
    return run_augmented_lagrangian(system, settings, context, method);
  return method.run(context);
}

}  // namespace contact::ddm
