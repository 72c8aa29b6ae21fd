// The model checks after the solve: motions the model cannot stand behind (docs/job-format.md, "Warnings").
//
// The model is linear and small-displacement: strains are the displacements' first derivatives and contact is
// measured on the drawn geometry (small sliding). Its answer is void where a body moves or turns far:
//   - a rotation theta turns into spurious strains of theta^2 / 2, as large as the elastic strains of stone, concrete
//     or steel (1e-4 to 1e-3) from theta = 0.05 rad (3 degrees): a body whose rigid rotation passes that is named;
//   - a displacement past 5 % of a body's size moves its contact points off the geometry they were measured on;
//   - a floating body (held by its contacts alone) that moved rigidly by more than 0.5 % of its size did not deform
//     into place (elastic motions are the strains, below 1e-3, times the distance to a support: a few of its sizes
//     in a wall): it closed a gap, or fell (a block drawn above its support, a modulus in the wrong units).
// A warning never changes the answer.
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <vector>

namespace contact::check {

constexpr double kLargeRotation = 0.05;           // radians
constexpr double kLargeDisplacement = 0.05;       // of the body's size (its bounding box's diagonal)
constexpr double kLargeRigidTranslation = 0.005;  // of a floating body's size

// The warnings for the bodies of `step` (the answer: the last step), at "/bodies/<a>".
std::vector<Warning> motion_warnings(const Problem& problem, const Step& step);

}  // namespace contact::check
