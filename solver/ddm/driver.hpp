// Runs one contact method, with or without augmented-Lagrangian updates, on a ContactSystem: what solve(), the
// load steps and the adaptive loop call.
#pragma once

#include "method.hpp"
#include "outcome_accumulator.hpp"

#include <memory>

namespace contact::ddm {

// The method, inside augmented-Lagrangian updates if the settings ask for them (the outcome counts them).
MethodOutcome run_enforced(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                           ContactMethod& method);

}  // namespace contact::ddm
