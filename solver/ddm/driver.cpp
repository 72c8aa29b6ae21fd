#include "driver.hpp"

#include "augmented_lagrangian.hpp"

#include <sstream>

namespace contact::ddm {

void run_enforced(ContactSystem& system, RunFrame& frame, ContactMethod& method) {
  const SolverSettings& settings = frame.settings();
  if (settings.enforcement == Enforcement::exact &&
      (settings.method == Method::neumann || settings.method == Method::robin)) {
    MethodOutcome& out = frame.outcome();
    out.stop_reason = StopReason::error;
    out.refused = true;  // a setting, not the loads: no increment is solved
    out.message = std::string("method ") + to_string(settings.method) +
                  " iterates on the penalty problem: enforcement exact is not available with it (use penalty, or "
                  "augmented_lagrangian for exact contact in the limit; or method interface_newton)";
    return;
  }
  if (settings.enforcement == Enforcement::augmented_lagrangian) return run_augmented_lagrangian(system, frame, method);
  method.run(frame);
}

}  // namespace contact::ddm
