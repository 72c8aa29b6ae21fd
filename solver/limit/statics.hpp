// The statics of a collapse analysis: the largest multiplier lambda of the live loads that the bodies, as rigid
// blocks (rigid_blocks.hpp), can carry besides the dead loads, with no-tension joints and their friction (Coulomb
// |q| <= mu z, Tresca |q| <= g, frictionless q = 0) at every mortar row: a linear program
//
//   maximise lambda  over lambda >= 0, z >= 0, q
//   such that, for every body and every rigid motion its supports leave it,
//     m . (sum_rows z_r N_r + q_r T_r + D + lambda L) = 0,       (the virtual work of the forces on the motion)
//   |q_r| <= mu z_r (Coulomb) or g (Tresca), q_r = 0 (frictionless),
//
// solved with GLPK's simplex. This is the lower-bound (static) theorem of limit analysis for associated friction:
// for the non-associated Coulomb friction of the elastic solve, lambda_c <= this bound (and for pure rocking,
// frictionless or sliding of one block they agree). The optimum's dual is a mechanism: a rigid velocity per body
// under which the joints open or slide as the associated flow rule allows and the live loads do positive work
// (mechanism.hpp names it).
#pragma once

#include "rigid_blocks.hpp"

#include <functional>
#include <string>
#include <vector>

namespace contact::limit {

struct StaticsAnswer {
  enum class Status {
    bounded,     // multiplier is the largest that holds; velocity is the mechanism at it
    unbounded,   // any multiple of the live loads is carried (they press the joints shut)
    infeasible,  // not even lambda = 0: the dead loads alone are not carried
    failed       // the LP library failed (message)
  };
  Status status = Status::failed;
  double multiplier = 0.0;
  // Per body: the mechanism's generalised velocity (vx, vy, omega) at its reference point, scaled so that the largest
  // velocity of a body's reference point plus size x |omega| is 1; zero for the bodies that do not move.
  std::vector<Eigen::Vector3d> velocity;
  std::string message;
};

// The statics with the loads `fixed` (per body, held) and `scaled` (per body, times lambda). With `cancelled`, the
// LP runs on a thread of its own and a cancel returns at once (Status::failed, message "cancelled").
StaticsAnswer largest_multiplier(const RigidBlocks& blocks, const std::vector<Resultant>& fixed,
                                 const std::vector<Resultant>& scaled, const std::function<bool()>& cancelled = {});

}  // namespace contact::limit
