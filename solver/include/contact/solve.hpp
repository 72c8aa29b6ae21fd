// The solver's public entry point: the server and the CLI depend on this header (and those it includes) only.
#pragma once

#include "contact/background_work.hpp"
#include "contact/problem.hpp"
#include "contact/result.hpp"
#include "contact/version.hpp"

namespace contact {

namespace parallel {
class TaskRunner;
}

// Solves the contact problem with the method of problem.solver. Reports every iteration to `observer` and
// stops with StopReason::cancelled within one iteration of `cancel` being set, and within a second when it is set
// during the set-up or an adaptive step's rebuild (assembly, factorisation): a factorisation cannot be
// interrupted, so solve() returns while it finishes on a thread of its own (contact/background_work.hpp). Never
// throws for a numerical failure (singular body, factorisation failure): it returns a Result with
// stop_reason == error and a message.
Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel);

// The same on the caller's executor of the per-body work: MPI ranks (solver/mpi/mpi_runner.hpp), where every
// rank calls solve() with the same problem and a `cancel` that the runner keeps equal on all ranks; each rank
// returns the same Result (the root reports progress and writes the file).
Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel, parallel::TaskRunner& runner);

}  // namespace contact
