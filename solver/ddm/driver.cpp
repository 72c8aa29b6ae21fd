#include "driver.hpp"

#include "augmented_lagrangian.hpp"

#include <sstream>
#include <string>
#include <utility>

namespace contact::ddm {

void run_enforced(const ContactSystem& system, RunFrame& frame, ContactMethod& method) {
  const SolverSettings& settings = frame.settings();
  // The job reader reports this for a job; a Problem built in code meets it here, in the same words.
  if (std::string conflict = settings_conflict(settings); !conflict.empty()) {
    MethodOutcome& out = frame.outcome();
    out.stop_reason = StopReason::error;
    out.refused = true;  // a setting, not the loads: no increment is solved
    out.message = std::move(conflict);
    return;
  }
  if (settings.enforcement == Enforcement::augmented_lagrangian) return run_augmented_lagrangian(system, frame, method);
  method.run(frame);
}

}  // namespace contact::ddm
