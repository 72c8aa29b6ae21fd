// Runs one contact method, with or without augmented-Lagrangian updates, on a ContactSystem: what the load steps
// and the adaptive loop call.
#pragma once

#include "method.hpp"

namespace contact::ddm {

// The method, inside augmented-Lagrangian updates if the frame's settings ask for them (the outcome counts them).
void run_enforced(const ContactSystem& system, RunFrame& frame, ContactMethod& method);

}  // namespace contact::ddm
