// First stick and slip sets for the friction Newton (friction_sets.hpp) from the same problem on coarser multiplier
// spaces (nested iteration), as nested_initial_guess (active_set.hpp) gives the frictionless active set.
//
// Why: from "every node in contact sticks" the semismooth Newton moves each slip front by about one node per step
// (the traction a slipping node sheds tips its neighbour over the bound only after the step), so the number of
// steps grows with the number of nodes the front crosses. On a coarser multiplier space the front crosses half as
// many; solved there first (recursively), the fine problem starts with its fronts within a node or two.
//
// The coarse space keeps every other contact node of each line (the ends always) and interpolates the others
// linearly in arc length, for the normal and the tangential multipliers alike (P >= 0, rows summing to at most 1).
// The coarse problem is the Galerkin one (P^T F P, P^T g, G P) with the friction conditions at the coarse nodes;
// since |q| <= mu z (or <= g) holds at the coarse nodes, it holds for their interpolation, so the prolonged
// multipliers are admissible. Pure linear algebra.
#pragma once

#include "active_set.hpp"
#include "friction_newton.hpp"
#include "friction_sets.hpp"

#include <vector>

namespace contact::linalg {

// One Newton step's linear system on the sets p (friction_sets.hpp): the rows of F lambda + g (+ G^T alpha) that
// must vanish, with the equalities G lambda = e; solved by sparse LU (UMFPACK). Fills x (lambda, h = g + F lambda
// + G^T alpha, other = alpha); false when it is singular.
bool solve_on_friction_sets(const SparseMatrix& F, const Eigen::VectorXd& g, const Equalities& eq,
                            const FrictionParametrization& p, FrictionIterate& x);

// The friction problem of one level: lambda = [z (the first m unknowns, normal rows); q], conditions per `rows`.
struct FrictionLevel {
  const SparseMatrix& F;
  const Eigen::VectorXd& g;
  const Equalities& eq;
  const std::vector<FrictionRow>& rows;
  const std::vector<char>& mask;    // the tangential unknowns (those without a row too: q = 0 there)
  Eigen::Index m = 0;               // normal unknowns
  const std::vector<int>& line;     // per normal unknown: its line (pair)
  const Eigen::VectorXd& position;  // per normal unknown: its arc length along its line
};

// The floating bodies' equilibrium as far as normal pressures alone can give it: the columns of the first m
// (normal) unknowns, without the rows they cannot meet (a motion only friction holds: sliding along a flat contact,
// a roller's spin).
Equalities normal_equalities(const Equalities& all, Eigen::Index m);

// c_j = 1 / F_jj, the inverse of the unknown's own compliance (the pressure or traction that would close its gap
// or slip alone); a row no body can move gets the largest scale. Every level's friction Newton uses it.
Eigen::VectorXd friction_scaling(const SparseMatrix& F);

// The first sets of `level` predicted from the coarse levels' solution, or false when there is no coarser level
// (fewer than `coarsest` normal unknowns) or a coarse problem could not be solved: the caller then starts as
// without. `coarse_steps` receives each coarse level's Newton steps (finest first).
bool nested_friction_sets(const FrictionLevel& level, FrictionSets& sets, std::vector<int>* coarse_steps = nullptr,
                          Eigen::Index coarsest = 16);

}  // namespace contact::linalg
