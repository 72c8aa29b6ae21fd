// What friction can hold, from statics alone, before a frictional solve: a load that no distribution of contact
// tractions can carry is refused at once, naming the bodies, the joint, the direction and the ratio, instead of
// being left to a Newton iteration that cannot converge (under force control the bodies would slide without end).
//
// The check: the contacts are grouped into flat joints (pairs whose rows share one normal and lie on one line: a
// bed joint of a masonry course, a block's base). Removing a joint's pairs splits the bodies into connected
// components (bodies linked by the other contacts); a component of bodies that float in all three rigid motions
// (no support of their own) is held only by the joint's pairs that cross its boundary. If those press it from one
// side (one inward normal m), their normal forces sum to N = -L.m for the component's total load L, and their
// tangential forces to |L.t|, which Coulomb friction bounds by mu N (the largest coefficient among them) and Tresca
// by the bounds times the contact lengths. |L.t| above that bound is shown: no solver can hold it. Anything else
// (curved contacts, components pressed from both sides, a load pulling off the joint) is left to the solve, which
// reports what it finds. One body on one flat contact is the simplest case (a block pushed along the ground).
#pragma once

#include <string>

#include "contact_system.hpp"

namespace contact::ddm {

// The message for the worst set of bodies friction cannot hold under the loads at load point `at`, or empty.
std::string friction_cannot_hold(const ContactSystem& system, const fem::LoadPoint& at);

// A ratio as the messages print it: four significant digits, trailing zeros kept (1.000, 1.083, 12.50).
std::string four_digits(double value);

}  // namespace contact::ddm
