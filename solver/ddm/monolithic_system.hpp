// The monolithic reference's system: every body's free unknowns stacked in one vector x (u_a = T_a x_a + g_a), the
// block-diagonal stiffness K and load b, and every contact row's weighted gap or slip as an affine function of x,
// g(x) = g0 + B x. ddm/monolithic.cpp solves it by its active sets, monolithic_friction.cpp by an augmented
// Lagrangian; both are independent of the interface machinery (Schur complements, dense active-set solves), which
// is what makes them a check on it.
#pragma once

#include "contact_system.hpp"
#include "run_state.hpp"
#include "../linalg/friction_sets.hpp"

#include <Eigen/SparseCore>

#include <vector>

namespace contact::ddm::monolithic {

using SpMat = Eigen::SparseMatrix<double>;

// All bodies stacked: block-diagonal K, right-hand side b, and the contact rows in x.
struct Stacked {
  std::vector<Eigen::Index> offset;  // per body, into x
  SpMat K;
  Eigen::VectorXd b;
  std::vector<Eigen::Index> row_offset;  // per pair, into the stacked rows
  SpMat B;                               // rows x n
  Eigen::VectorXd g0, D, c;              // per row: weighted gap at x = 0, D, and the active-set scaling
  std::vector<int> row_pair, row_index;  // per row: its pair and its row in the pair
  // Friction: the tangential rows follow the normal ones (tangential_offset per pair, -1 if frictionless).
  std::vector<Eigen::Index> tangential_offset;
  std::vector<linalg::FrictionRow> friction;
  fem::LoadPoint at;  // the load point the loads (b) and prescribed values (g0, to_bodies) are taken at
};

// The system at the state's load point; with `shift_by_multipliers` the gaps shifted by the augmented Lagrangian's
// multipliers (penalty enforcement).
Stacked stack(const ContactSystem& system, const RunState& state, bool shift_by_multipliers);

// x as each body's displacements at the system's load point.
Displacements to_bodies(const ContactSystem& system, const Stacked& s, const Eigen::VectorXd& x);
// The normal rows of a vector over the rows, per pair; and the tangential rows (empty for a frictionless pair).
Pressures split_rows(const ContactSystem& system, const Stacked& s, const Eigen::VectorXd& rows);
Pressures split_tangential(const ContactSystem& system, const Stacked& s, const Eigen::VectorXd& rows);

}  // namespace contact::ddm::monolithic
