// The adaptive loop (paper section 3; docs/algorithm.md, "h-adaptivity"), both ways:
//  * paper: every iteration does one Neumann update (paper (16)-(17)), then estimates and refines the adaptive
//    bodies; the refined mesh starts the next iteration (the iterate transferred to it). Stops when the DDM
//    criterion holds and no cell is marked.
//  * converge_then_refine: solve on the current meshes with the chosen method (and enforcement), estimate,
//    mark, refine, repeat until nothing is marked or a limit (max_steps, max_level, max_dofs) is hit.
// Every mesh state is returned as a Step (fields, refinement level and indicator per cell).
#pragma once

#include "../ddm/driver.hpp"
#include "../ddm/step_log.hpp"
#include "contact/result.hpp"

namespace contact::adapt {

// `working` is the problem the system was built from; its meshes are refined in place. Builds the frame's outcome.
void run_adaptive(Problem& working, ddm::ContactSystem& system, ddm::RunFrame& frame, ddm::ContactMethod& method,
                  ddm::StepLog& steps);

}  // namespace contact::adapt
