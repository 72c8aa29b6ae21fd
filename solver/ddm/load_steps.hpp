// Load steps (Problem::loading): the same contact problem under growing (or any) load factors. Every prescribed
// displacement, traction, force and body force is scaled by the step's factor (the run state's load point,
// run_state.hpp, which this loop moves; the factorisations stay), each step is solved with the chosen method starting
// from the previous step's answer (the fixed-point schemes: its displacements; interface Newton: its pressures under
// the penalty, nested coarse solves with exact contact, sparse_direct.cpp), and each step's fields become one result
// Step with its factor, recorded in `steps` (which keeps all or the last, StepLog). The iteration reports run on across
// the steps.
#pragma once

#include "driver.hpp"
#include "step_log.hpp"

namespace contact::ddm {

// The fields of a solved state (a load step, a collapse analysis's trial) as a result Step.
Step step_of(const ContactSystem& system, const MethodOutcome& outcome, const RunState& state);

// The last two states that held along the loading (steps or their cut sub-steps): where a step fails, the
// increment between them shows the collapse's mechanism, if it is one (limit/elastic_mechanism.hpp).
struct HeldPath {
  Displacements before;  // the state that held before `last` (empty: none did)
  MethodOutcome last;    // the last state that held (u empty: none did)
  RunState last_state;   // its load point and slip origins
};

// Returns the last two states that held (what the verdict on a failed step reads).
HeldPath run_load_steps(const ContactSystem& system, const std::vector<double>& factors, RunFrame& frame,
                        ContactMethod& method, StepLog& steps);

}  // namespace contact::ddm
