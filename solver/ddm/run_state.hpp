// The state of a run that its outer loops move while the discretisation stays fixed: where the run is on the load
// path, friction's slip origins and the augmented Lagrangian's multipliers. The ContactSystem (the meshes, the pairs'
// mortar operators, the bodies' factorisations) changes only when it is rebuilt; every method receives it const and
// reads the state beside it (RunFrame::state()).
//
// Who writes what: the load-step loop (load_steps.cpp) moves `load` and, once a step or sub-step holds, sets the slip
// origins from its displacements (ContactSystem::tangential_jumps); the augmented-Lagrangian loop
// (augmented_lagrangian.cpp) sets the multipliers; adaptivity drops the per-pair values when the pairs are
// rediscretised (ContactSystem::rebuild). Nothing else writes it.
#pragma once

#include "../fem/load_point.hpp"

#include <Eigen/Core>

#include <vector>

namespace contact::ddm {

using Displacements = std::vector<Eigen::VectorXd>;  // one full dof vector per body
using Pressures = std::vector<Eigen::VectorXd>;      // one row vector per contact pair

struct RunState {
  fem::LoadPoint load;
  // Per pair: the weighted tangential jump w at the last accepted state (the end of the previous load step or
  // sub-step): friction acts on the slip w - origin (mortar/pair.hpp). Absent or empty: zero.
  Pressures slip_origin;
  // Per pair: the augmented-Lagrangian multipliers per row; the penalty pressure is then max(0, lambda - g / theta).
  // Absent or empty: none.
  Pressures multipliers;

  // Pair k's values if it has one per row (`rows` of them), else null.
  const Eigen::VectorXd* slip_origin_of(size_t k, Eigen::Index rows) const { return row_values(slip_origin, k, rows); }
  const Eigen::VectorXd* multipliers_of(size_t k, Eigen::Index rows) const { return row_values(multipliers, k, rows); }
  // The per-pair values belong to one discretisation of the pairs: dropped when it is rebuilt.
  void drop_pair_values() {
    slip_origin.clear();
    multipliers.clear();
  }

 private:
  static const Eigen::VectorXd* row_values(const Pressures& v, size_t k, Eigen::Index rows) {
    return k < v.size() && v[k].size() == rows ? &v[k] : nullptr;
  }
};

}  // namespace contact::ddm
