// Whether the contacts in contact at a solution hold every floating body: the check that interface Newton makes
// on its active set (linalg/active_set.cpp: the equilibrium rows its contact nodes leave without support), made on a
// finished result, for the methods that do not make it themselves (the monolithic reference, which otherwise
// returns a zero displacement for a body whose rigid motion the solution leaves undetermined).
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <string>

namespace contact {

// Every floating body of `step` (BodyField::free_motions not empty) whose rigid motions are not all held by its
// prescribed displacement components and the normals of the contact nodes in contact (PairField::active) of the
// pairs it takes part in: a combination of translations and rotation that moves no held point along its held
// direction is left free, and the solution is not unique. Returns one sentence per such body, in the words of
// interface Newton's refusal ("body 'cap' floats (...) and no contact holds it: ..."), or "" when all are held.
std::string unheld_floating_bodies(const Problem& problem, const Step& step);

}  // namespace contact
