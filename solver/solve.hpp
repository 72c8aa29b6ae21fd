// The solver's public entry point: the server and the CLI depend on this header (and those it includes) only.
#pragma once

#include "problem.hpp"
#include "result.hpp"

namespace contact {

// Solves the contact problem with the method of problem.solver. Reports every iteration to `observer` and
// stops with StopReason::cancelled within one iteration of `cancel` being set. Never throws for a numerical
// failure (singular body, factorisation failure): it returns a Result with stop_reason == error and a message.
Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel);

// The version string recorded in result files.
const char* solver_version();

}  // namespace contact
