// The collapse mechanism the elastic solution itself shows (issue 48 item 2), as against the rigid-block statics'
// (statics.hpp), whose mechanism is the associated one at the statics bound.
//
// Near the collapse the capacity curve softens: a small raise of the multiplier moves the bodies that are about to
// collapse far more than it deforms them. So the displacement increment between the last two states that held is,
// body by body, nearly a rigid motion, and the last held state's contact sets say what each joint can do. In phases:
//  1. Fit: each body's increment by its least-squares rigid motion (vx, vy, omega at its reference point), and how
//     much of the increment that rigid part explains.
//  2. Joints, from the last held state: nothing in contact (beyond an elastic fringe of 0.1 % of its force), free;
//     most of its normal force on slipping nodes (or no friction), sliding: no relative normal motion where it
//     bears; its contact within a third of its length, a hinge: no relative motion at the node nearest its centre of
//     pressure (where the thrust passes), unless the fitted motion hardly moves it (then shut); else shut.
//  3. Exact: the fitted velocities projected (least squares) onto the rigid motions those joints and the supports
//     allow; a row the result would make overlap, or slip the way its friction pushed, is held too and the fit
//     projected again, until no row does. If nothing is left moving, the hinge threshold is lowered (an arch's last
//     hinge forms late, so the increment turns it little).
//  4. Described in words (mechanism.hpp) and checked: no joint overlaps, each sliding joint slides against the
//     friction force it carried at the last held state, and the live loads do positive work on the motion. A
//     mechanism that fails the check is not reported as the collapse's (the caller names the statics' one, saying
//     why).
#pragma once

#include "rigid_blocks.hpp"

#include "../ddm/run_state.hpp"
#include "contact/result.hpp"

#include <vector>

namespace contact::limit {

struct ElasticMechanism {
  Mechanism mechanism;       // source "elastic"; kind "" when none was found
  bool admissible = false;   // the check passed
  double rigid_share = 0.0;  // of the moving bodies' increment, the share (by norm) its rigid fit explains
  double kept = 0.0;         // the cosine between the mechanism and the fitted rigid motion it was projected from
  std::string check;         // the check in words: what passed, or what failed and where (mechanism.check adds,
                             // when it passed, how rigid the increment was and the cosine `kept`)
};

// From the held states `before` and `after` (displacements of the bodies this process owns; a collective call on
// MPI ranks), the state `held` (= after) as a result step, and the live loads' resultants per body at multiplier 1.
ElasticMechanism elastic_mechanism(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                                   const ddm::Displacements& before, const ddm::Displacements& after, const Step& held,
                                   const std::vector<Resultant>& live);

}  // namespace contact::limit
