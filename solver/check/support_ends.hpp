// A model check after the solve: contact force carried past the end of a master edge (docs/job-format.md,
// "Warnings").
//
// The dual mortar method puts a multiplier's force at its slave node (mortar/pair.hpp: Gs(r, i) = D_r nu_r at
// i = r). A slave node past the end of the master edge whose multiplier still covers part of it (its segment, or
// the coarse-grained multiplier segment where the slave is finer than the master, reaches back over the master)
// carries its share there: past the support. Where the pressure concentrates at such a node - a block whose centre
// lies past its support's edge by less than a multiplier segment - the answer holds a block the support could not:
// the moment arm is off by up to that segment. Measured: a 1 x 1 block whose centre overhangs a ground edge by 0.2,
// the ground's segments 0.25 long, stands with its whole weight on the slave node at x = 2.2, 0.2 past the ground.
// A warning never changes the answer; finer edges there (segments well under the overhang) remove it.
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <vector>

namespace contact::check {

// A pair is named when more than this share of its normal force sits on slave nodes past its master edge's ends.
constexpr double kForcePastTheEnd = 0.01;

// The warnings for the pairs of `step` (the answer: the last step), at "/contacts/<k>".
std::vector<Warning> support_end_warnings(const Problem& problem, const Step& step);

}  // namespace contact::check
