// The solver's public entry point: the server and the CLI depend on this header (and those it includes) only.
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

namespace contact {

namespace parallel {
class TaskRunner;
}

// Solves the contact problem with the method of problem.solver. Reports every iteration to `observer` and
// stops with StopReason::cancelled within one iteration of `cancel` being set, and within a second when it is set
// during the set-up or an adaptive step's rebuild (assembly, factorisation): a factorisation cannot be
// interrupted, so solve() returns while it finishes on a thread of its own (see background_work_running()). Never throws for a numerical
// failure (singular body, factorisation failure): it returns a Result with stop_reason == error and a message.
Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel);

// The same on the caller's executor of the per-body work: MPI ranks (solver/mpi/mpi_runner.hpp), where every
// rank calls solve() with the same problem and a `cancel` that the runner keeps equal on all ranks; each rank
// returns the same Result (the root reports progress and writes the file).
Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel, parallel::TaskRunner& runner);

// Factorisations a cancel left running (each ends within seconds and frees its memory). A program about to exit
// waits for them (wait_for_background_work with a bound) or, if it must exit at once, ends with std::_Exit after
// flushing its output: exiting normally while one runs may crash in the libraries' exit handlers.
bool background_work_running();
// How many of them run now: each holds a core and its memory until it ends (contactd counts them against its
// workers before it starts another job).
int abandoned_background_work();
// Waits until no such work runs or `seconds` passed; true when none runs.
bool wait_for_background_work(double seconds);

// The version string recorded in result files.
const char* solver_version();

}  // namespace contact
