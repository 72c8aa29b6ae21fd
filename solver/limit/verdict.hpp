// Why a step could not be solved, by statics: the loads where it stopped, all of them scaled by one multiplier, on
// the bodies as rigid blocks (statics.hpp). If the blocks carry less than the whole loads, there is no equilibrium
// whatever the solver, and the statics' dual is the mechanism (a collapse: "no_equilibrium"); if they carry them,
// statics does not explain the failure ("solver_failed": the solver, or non-associated friction, which can fail
// below the associated bound).
#pragma once

#include "rigid_blocks.hpp"

#include "../ddm/load_steps.hpp"

#include "contact/result.hpp"

namespace contact::limit {

// The verdict on a step that stopped at `at`, in a CollapseResult (verdict, statics_bound: the fraction of the
// loads carried, mechanism, words). `what` names the loads in the words ("the loads", "the dead loads"); a cancel
// (`cancelled`) returns at once, the verdict then without statics.
//
// Where statics carries the loads and friction is Coulomb's, the elastic states that held last (`path`, the loading's
// last two) may still show a mechanism (elastic_mechanism.hpp) on which the loads' increment to `at` does work:
// non-associated friction gives way below the associated bound. Then the verdict is "collapse" with that mechanism
// (the statics' kept as statics_mechanism; `held`, `failed` unset: the words say where on the load path); else
// "solver_failed", saying that either may be the cause.
CollapseResult judge_failed_step(const ddm::ContactSystem& system, const fem::LoadPoint& at, const std::string& what,
                                 const std::function<bool()>& cancelled = {}, const ddm::HeldPath* path = nullptr);

}  // namespace contact::limit
