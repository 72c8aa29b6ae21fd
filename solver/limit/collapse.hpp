// The collapse analysis (Problem::collapse, docs/limit-analysis.md): once the loading's steps have brought the dead
// loads on and held, the live loads' multiplier lambda is raised and the collapse multiplier lambda_c bracketed.
//
//  1. The statics first (statics.hpp): the bodies as rigid blocks with associated friction carry at most lambda_s,
//     an upper bound of lambda_c (the elastic solution's contact forces are forces of the blocks); above it a trial
//     would be refused whatever the solver, so lambda_s (1 + tol/4) is the bracket's top before any solve fails.
//  2. Trials, each one load increment from the last state that held (its displacements the warm start, its
//     tangential jumps friction's slip origin): first half of lambda_s (or the job's `first`, or 1 without a bound),
//     then just under the top, lambda_s (1 - tol/4): where friction is as associated (rocking, one block sliding,
//     frictionless) that holds and the bracket is closed in two solves. Without a bound (the live loads press the
//     joints shut) the next trial is max_multiplier.
//  3. Once a trial fails, bisection between the last that held and the first that failed, each trial again from
//     the last held state (one increment: about one step's cost), until the bracket is `tolerance` relative.
//
// Every state that held is a result step with its multiplier (the capacity curve); the run's answer is the last
// one. The verdict names the mechanism: the elastic solution's own near the limit when it passes its check
// (elastic_mechanism.hpp), else the statics' at its bound (mechanism.hpp), and the joints that open or slip at the
// last held state.
#pragma once

#include "../ddm/load_steps.hpp"

namespace contact::limit {

// After run_load_steps held: raises the live loads; fills `out` and leaves the last held state as the frame's
// outcome (converged, its message the verdict) unless the run was cancelled.
void run_collapse(const ddm::ContactSystem& system, const CollapseSpec& spec, ddm::RunFrame& frame,
                  ddm::ContactMethod& method, ddm::StepLog& steps, CollapseResult& out);

}  // namespace contact::limit
