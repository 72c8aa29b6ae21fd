// The contact problem reduced to the nodal multipliers z of all pairs (one per contact node, stacked pair by
// pair): each body enters through its Schur complement on its contact unknowns.
//
// With B_a the map from body a's dofs to the weighted gaps (-Gs rows where a is the slave, +Gm where it is the
// master), the contact forces on body a are B_a^T z, so its displacements are u_a = u_a^free + K_a^-1 B_a^T z and
//   g(z) = g_free + F z,   F = sum_a B_a K_a^-1 B_a^T = sum_a W_a^T W_a,   W_a = L_ZZ,a^-1 B_Z,a^T,
// where L_ZZ,a is the trailing block of body a's Cholesky factor with its contact unknowns Z ordered last
// (fem/cholesky.hpp) and B_Z,a the columns of B_a T_a on Z. Building F_a costs, per body and in parallel, one
// dense triangular solve with |Z| x (its multipliers) right-hand sides; nothing of the size of the body is
// stored besides its factorisation.
//
// F is kept per body: F_a is dense on body a's own rows only, so a contact node couples only to the nodes of the
// two bodies it joins, and F as a whole is a sparse block matrix (a wall of bricks: a few dozen entries per row,
// whatever the number of bricks). It is applied block by block (each process its own bodies' blocks) or assembled
// as a sparse matrix for a direct solver; never as one dense matrix. F is symmetric positive semi-definite, and
// definite when every contact node can move (a node whose both sides are held gives a zero row: see
// docs/algorithm.md).
//
// Floating bodies (held by their contacts alone, FETI's case): K_a is singular with the rigid modes R_a as its
// kernel; the factorisation with a few dofs fixed gives a generalised inverse K_a^+, and
//   u_a = K_a^+ (f_a + B_a^T z) + R_a alpha_a,   solvable only if R_a^T (f_a + B_a^T z) = 0,
// so the gaps gain G^T alpha and the equilibrium of every floating body G z = e joins the problem, with
// G = [(B_a R_a)^T] and e = [-R_a^T f_a]: the natural coarse space of FETI (Farhat & Roux 1991, Dostal's TFETI),
// see coarse_space.hpp.
#pragma once

#include "../../linalg/active_set.hpp"
#include "../contact_system.hpp"

namespace contact::ddm {

using linalg::Equalities;
using linalg::SparseMatrix;

class InterfaceProblem {
 public:
  struct Options {
    // The iterative solver's preconditioner blocks (feti.hpp): none, lumped (B K B^T on the contact unknowns) or
    // Dirichlet (B S B^T with S the body's Schur complement on them: the trailing block of its factor).
    InterfacePreconditioner preconditioner = InterfacePreconditioner::none;
    // Every process holds every body's block (a direct solver assembles them all); false: each process keeps
    // only its own bodies' blocks (the iterative solver applies them where they live).
    bool replicate_blocks = true;
    // Friction pairs add a tangential row per contact node (after all the normal rows): the weighted slip of this
    // load step, conjugate to the tangential multiplier (mortar/pair.hpp).
    bool friction = false;
  };

  // Needs a system built with Factorization::interface. Free responses (at load point `at`) and Schur complements,
  // bodies in parallel through `runner`.
  InterfaceProblem(const ContactSystem& system, parallel::TaskRunner& runner, const fem::LoadPoint& at = {})
      : InterfaceProblem(system, runner, Options{}, at) {}
  InterfaceProblem(const ContactSystem& system, parallel::TaskRunner& runner, const Options& options,
                   const fem::LoadPoint& at = {});

  Eigen::Index size() const { return size_; }
  Eigen::Index normal_size() const { return static_cast<Eigen::Index>(offset_.back()); }
  // The first tangential row of pair k (-1: frictionless, or friction not asked for).
  Eigen::Index tangential_offset(size_t pair) const { return tangential_offset_[pair]; }
  // Weighted gaps (and slips) with no contact force, at the state's load point (the bodies' part scales with its
  // factor) and friction pairs' slip origins.
  Eigen::VectorXd free_gap(const RunState& state) const;
  // Recomputes the bodies' free responses for the loads at `at`: needed when a step's loads are not a multiple of
  // the previous ones (conditions with their own history). One solve per body.
  void refresh_loads(parallel::TaskRunner& runner, const fem::LoadPoint& at);
  const Eigen::VectorXd& weights() const { return D_; }  // area of every row, stacked
  Eigen::Index offset(size_t pair) const { return offset_[pair]; }
  const ContactSystem& system() const { return system_; }

  // One body's part of the interface operator: its rows (stacked numbering) and its dense blocks on them.
  struct Block {
    std::vector<Eigen::Index> rows;
    Eigen::MatrixXd F;               // compliance (empty where this process does not hold it)
    Eigen::MatrixXd preconditioner;  // B S B^T or B K B^T (empty unless asked for)
  };
  const std::vector<Block>& blocks() const { return blocks_; }
  bool replicated() const { return options_.replicate_blocks; }

  // F (weighted gap per unit nodal pressure) as a sparse matrix: needs every block (replicate_blocks).
  SparseMatrix assemble() const;
  // y = F x from the blocks this process holds, summed over the processes by `runner` (returns its cancel
  // answer, TaskRunner::sum).
  bool apply(const Eigen::VectorXd& x, Eigen::VectorXd& y, parallel::TaskRunner& runner) const;
  // y = sum_a B_a X_a B_a^T x with the preconditioner blocks, scaled to approximate F^-1 (feti.hpp).
  bool apply_preconditioner(const Eigen::VectorXd& x, Eigen::VectorXd& y, parallel::TaskRunner& runner) const;
  // The diagonal of F (every process holds all of it).
  const Eigen::VectorXd& diagonal() const { return diagonal_; }

  // Splits a stacked vector into one vector per pair (its normal rows), and the reverse; split_tangential gives
  // the tangential rows (empty for frictionless pairs).
  Pressures split(const Eigen::VectorXd& stacked) const;
  Pressures split_tangential(const Eigen::VectorXd& stacked) const;
  Eigen::VectorXd stack(const Pressures& per_pair) const;

  // Floating bodies: each one's rigid-mode amplitudes alpha_a are rows [offset, offset + count) of alpha.
  struct Floating {
    size_t body = 0;
    Eigen::Index offset = 0, count = 0;
  };
  const std::vector<Floating>& floating() const { return floating_; }
  // The equilibrium of the floating bodies, G z = e, at load point `at` (empty without floating bodies).
  Equalities equilibrium(const fem::LoadPoint& at) const;
  // The number of rigid-mode amplitudes (rows of G).
  Eigen::Index rigid_unknowns() const { return equilibrium_.G.rows(); }

  // The bodies' displacements for pressures z and rigid-mode amplitudes alpha (empty without floating bodies) under
  // their loads at `at`: one solve per body, in parallel.
  Displacements displacements(const Eigen::VectorXd& z, const Eigen::VectorXd& alpha, const fem::LoadPoint& at) const;

 private:
  struct BodyParts;  // what one body's task computes
  void compute_body(size_t a, const fem::LoadPoint& at, BodyParts& out) const;
  void assemble_equilibrium(const std::vector<BodyParts>& parts);
  bool apply_blocks(const Eigen::VectorXd& x, Eigen::VectorXd& y, parallel::TaskRunner& runner,
                    bool preconditioner) const;
  // apply_blocks' split of the blocks this process applies over its threads: runs [first[c], first[c + 1]) of
  // `blocks`, and a vector per run to sum into. Made at the first product with a runner and kept (the products are
  // the iterative solver's hot path: thousands per solve); one per kind (F, preconditioner). The products of one
  // problem are not made concurrently (one solve drives them), so the cache needs no lock.
  struct Split {
    const parallel::TaskRunner* runner = nullptr;  // made for this runner with this many threads
    unsigned concurrency = 0;
    std::vector<size_t> blocks, first;
    std::vector<Eigen::VectorXd> parts;
  };
  Split& split(parallel::TaskRunner& runner, bool preconditioner) const;

  const ContactSystem& system_;
  Options options_;
  std::vector<Eigen::Index> offset_, tangential_offset_;
  Eigen::Index size_ = 0;
  std::vector<Block> blocks_;
  Eigen::VectorXd gap0_, g_loads_, D_, diagonal_, inverse_weight_;  // g_loads_: at the loading's factor factor_
  double factor_ = 1.0;
  std::vector<Floating> floating_;
  Equalities equilibrium_;
  mutable Split split_[2];  // [0]: F, [1]: the preconditioner
};

}  // namespace contact::ddm
