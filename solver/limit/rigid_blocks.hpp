// The bodies of a contact problem seen as rigid blocks: what the statics of a collapse analysis works on
// (statics.hpp). Each body keeps three generalised coordinates, the rigid motion (vx, vy, omega) at its reference
// point (the mean of its nodes); a force field on the body reduces to its resultant there (Fx, Fy, M).
//
// The joints are the contact pairs' mortar rows, exactly as the elastic solve discretises them: row r of a pair
// pushes its slave with the nodal forces -Gs(r, :) z_r and its master with +Gm(r, :) z_r (mortar/pair.hpp), and its
// friction with -Ts(r, :) q_r and +Tm(r, :) q_r. Their resultants per unit z_r and q_r are the columns of the
// statics; so any contact forces of the elastic solution are forces of the rigid blocks too, and a load that the
// blocks cannot carry cannot be carried by the elastic bodies either (the statics bound is an upper bound of the
// elastic analysis's collapse multiplier, as for associated friction it is of the non-associated one).
//
// The supports: a body's prescribed displacement components leave it the rigid motions that move none of those
// components (`motions`, an orthonormal basis of them in (vx, vy, L omega), L the body's size); its equilibrium is
// asked along those only (the supports carry the rest). A clamped body has none: it is ground.
#pragma once

#include "../ddm/contact_system.hpp"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace contact::limit {

using Resultant = Eigen::Vector3d;  // (Fx, Fy, M) at a body's reference point, M anticlockwise

struct RigidBody {
  std::string name;
  Eigen::Vector2d reference = Eigen::Vector2d::Zero();  // the mean of its nodes
  double size = 1.0;                                    // the diagonal of its bounding box
  Eigen::MatrixXd motions;  // 3 x k: the admissible rigid motions (vx, vy, size x omega), orthonormal columns
};

// One mortar row of a pair: its generalised forces per unit pressure and per unit tangential multiplier.
struct JointRow {
  size_t pair = 0;
  int row = 0;
  int node = 0;                                      // the row's slave node (its index in the slave's mesh)
  Eigen::Vector2d point = Eigen::Vector2d::Zero();   // the row's slave node
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();  // the slave's outward normal there (mortar/pair.hpp)
  Eigen::Vector2d tangent = Eigen::Vector2d::Zero();
  Resultant slave_normal = Resultant::Zero(), master_normal = Resultant::Zero();
  Resultant slave_tangential = Resultant::Zero(), master_tangential = Resultant::Zero();
};

struct RigidBlocks {
  std::vector<RigidBody> bodies;
  std::vector<JointRow> rows;
  std::vector<int> slave_of_pair, master_of_pair;  // per pair: its bodies
  std::vector<FrictionSpec> friction_of_pair;      // per pair: the law its rows obey
};

// The blocks of the system's bodies and pairs.
RigidBlocks rigid_blocks(const ddm::ContactSystem& system);

// Every body's external loads at load point `at` (tractions, forces, body forces, weight) as its resultant: each
// computed by the process that owns the body, then summed over the processes (a collective call on MPI ranks).
std::vector<Resultant> load_resultants(const ddm::ContactSystem& system, const RigidBlocks& blocks,
                                       const fem::LoadPoint& at);

// The velocity at point x of a body moving with generalised velocity v = (vx, vy, omega) at `reference`.
inline Eigen::Vector2d velocity_at(const Eigen::Vector3d& v, const Eigen::Vector2d& reference,
                                   const Eigen::Vector2d& x) {
  const Eigen::Vector2d d = x - reference;
  return {v[0] - v[2] * d.y(), v[1] + v[2] * d.x()};
}

}  // namespace contact::limit
