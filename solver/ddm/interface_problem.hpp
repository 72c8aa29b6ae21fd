// The contact problem reduced to the nodal multipliers z of all pairs (one per contact node, stacked pair by
// pair): each body enters through its Schur complement on its contact unknowns.
//
// With B_a the map from body a's dofs to the weighted gaps (-Gs rows where a is the slave, +Gm where it is the
// master), the contact forces on body a are B_a^T z, so its displacements are u_a = u_a^free + K_a^-1 B_a^T z and
//   g(z) = g_free + F z,   F = sum_a B_a K_a^-1 B_a^T = sum_a W_a^T W_a,   W_a = L_ZZ,a^-1 B_Z,a^T,
// where L_ZZ,a is the trailing block of body a's Cholesky factor with its contact unknowns Z ordered last
// (fem/cholesky.hpp) and B_Z,a the columns of B_a T_a on Z. Building F costs, per body and in parallel, one
// dense triangular solve with |Z| x (its multipliers) right-hand sides; nothing of the size of the body is
// stored besides its factorisation. F is symmetric positive semi-definite, and definite when every contact node
// can move (a node whose both sides are held gives a zero row: see docs/algorithm.md).
//
// Floating bodies (held by their contacts alone, FETI's case): K_a is singular with the rigid modes R_a as its
// kernel; the factorisation with a few dofs fixed gives a generalised inverse K_a^+, and
//   u_a = K_a^+ (f_a + B_a^T z) + R_a alpha_a,   solvable only if R_a^T (f_a + B_a^T z) = 0,
// so the gaps gain G^T alpha and the equilibrium of every floating body G z = e joins the problem, with
// G = [(B_a R_a)^T] and e = [-R_a^T f_a] (the coarse problem of FETI; Farhat & Roux 1991, Dostal's TFETI).
#pragma once

#include "active_set.hpp"
#include "contact_system.hpp"

namespace contact::ddm {

class InterfaceProblem {
 public:
  // Needs a system built with Factorization::interface. Free responses and Schur complements, bodies in
  // parallel through `runner`.
  InterfaceProblem(const ContactSystem& system, TaskRunner& runner);

  Eigen::Index size() const { return F_.rows(); }
  const Eigen::MatrixXd& compliance() const { return F_; }    // F (weighted gap per unit nodal pressure)
  // Weighted gaps with no contact force, at the system's current load factor (the bodies' part scales with it).
  Eigen::VectorXd free_gap() const;
  const Eigen::VectorXd& weights() const { return D_; }       // area of every row, stacked
  Eigen::Index offset(size_t pair) const { return offset_[pair]; }

  // Splits a stacked vector into one vector per pair, and the reverse.
  Pressures split(const Eigen::VectorXd& stacked) const;
  Eigen::VectorXd stack(const Pressures& per_pair) const;

  // Floating bodies: each one's rigid-mode amplitudes alpha_a are rows [offset, offset + count) of alpha.
  struct Floating {
    size_t body = 0;
    Eigen::Index offset = 0, count = 0;
  };
  const std::vector<Floating>& floating() const { return floating_; }
  // The equilibrium of the floating bodies, G z = e, at the current load factor (empty without floating bodies).
  Equalities equilibrium() const;

  // The bodies' displacements for pressures z and rigid-mode amplitudes alpha (empty without floating bodies):
  // one solve per body, in parallel.
  Displacements displacements(const Eigen::VectorXd& z, const Eigen::VectorXd& alpha, TaskRunner& runner) const;

 private:
  const ContactSystem& system_;
  std::vector<Eigen::Index> offset_;
  Eigen::MatrixXd F_;
  Eigen::VectorXd gap0_, g_loads_, D_;  // g_loads_: the bodies' free responses' gaps at load factor factor_
  double factor_ = 1.0;
  std::vector<Floating> floating_;
  Equalities equilibrium_;
};

}  // namespace contact::ddm
