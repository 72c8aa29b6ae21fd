// A collapse mechanism in words: from the statics' mechanism (a rigid velocity per body, statics.hpp) the bodies
// that move and how (translating, or turning about their instantaneous centre) and what each joint does (a hinge
// about a point of it, sliding along it, opening, or opening and sliding), and the kind of the whole: overturning
// (one hinge under the bodies that move), sliding, hinging (several hinges), mixed, lift-off (joints only open: a load
// the wrong way) or unsupported (bodies move and no joint takes part: nothing holds them).
#pragma once

#include "rigid_blocks.hpp"

#include "contact/result.hpp"

#include <vector>

namespace contact::limit {

Mechanism describe_mechanism(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                             const std::vector<Eigen::Vector3d>& velocity);

// A number as the verdicts print it: four significant digits.
std::string shown(double value);
// A point as "(x, y)" with shown() coordinates.
std::string shown(const Eigen::Vector2d& point);

}  // namespace contact::limit
