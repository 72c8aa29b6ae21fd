// All bodies and contact pairs of a problem on fixed meshes: each pair's mortar discretisation, each body's
// factorised solver, plus the evaluations every method needs (contact forces, contact-zone normal displacements,
// per-iteration reports, final fields). Rebuilt when a mesh changes.
//
// Contact pressures are per pair one value per mortar row (contact node), positive in compression
// (mortar/pair.hpp); `Pressures` holds them for all pairs.
#pragma once

#include "../mortar/pair.hpp"
#include "../fem/body_solver.hpp"
#include "contact/problem.hpp"
#include "contact/result.hpp"
#include "../parallel/task_runner.hpp"
#include "run_state.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace contact::ddm {

class ContactSystem {
 public:
  enum class Factorization {
    none,       // assembly only (the monolithic reference factorises a coupled system itself)
    plain,      // each body factorised with the default fill-reducing ordering
    interface,  // each body's contact unknowns ordered last: Schur complements for the interface problem
  };

  // Discretises every pair, then assembles every body and factorises them as asked, in parallel through
  // `runner`, which every per-body work of the system runs on from then on. Check ok() / error(). With `stop` (the
  // run's stop check, RunFrame::stop_check), a stop asked during the assembly or a factorisation ends the set-up
  // within a poll (fem/body_solver.hpp): then cancelled() and not ok(), and the system must not be used.
  ContactSystem(const Problem& problem, parallel::TaskRunner& runner,
                Factorization factorization = Factorization::plain, std::function<bool()> stop = {});

  // After the meshes of the bodies flagged in `changed` were refined (in the Problem this system refers to):
  // rediscretises every pair and reassembles and refactorises the changed bodies, and any other body whose
  // interface unknowns changed (an unchanged body keeps its factorisation). The run state's per-pair values (slip
  // origins, multipliers) belonged to the old pairs: they are dropped. Check ok(); a cancel (as for the constructor)
  // leaves cancelled() true and the system unusable.
  void rebuild(const std::vector<char>& changed, RunState& state, const std::function<bool()>& stop = {});

  bool ok() const { return error_.empty() && !cancelled_; }
  bool cancelled() const { return cancelled_; }
  const std::string& error() const { return error_; }
  // Assembly and factorisation seconds of all bodies built so far (summed over bodies).
  double total_factorization_seconds() const { return factorization_seconds_; }

  const Problem& problem() const { return problem_; }
  parallel::TaskRunner& runner() const { return runner_; }  // the processes and threads it was built on
  size_t n_bodies() const { return bodies_.size(); }
  const fem::BodySolver& body(size_t a) const { return *bodies_[a]; }
  const std::vector<mortar::PairDiscretization>& pairs() const { return pairs_; }
  const std::vector<mortar::PenaltyChoice>& penalties() const { return penalties_; }
  // The pairs body a is the slave or the master of (indices into pairs(), in order, each once).
  const std::vector<size_t>& pairs_of(size_t a) const { return pairs_of_body_[a]; }
  double setup_seconds() const { return setup_seconds_; }
  double factorization_seconds() const { return factorization_seconds_; }  // summed over bodies

  // Some condition has its own load history: the loads of a step are then not a multiple of another step's.
  bool has_histories() const;
  bool has_friction() const { return problem_.has_friction(); }
  // The weighted tangential jump of every friction pair at displacements u (empty for the others): friction acts
  // on slip increments, and the jump where a load step ends is the next step's slip origin (RunState).
  Pressures tangential_jumps(const Displacements& u) const;

  // The penalty pressures of displacements u (paper (16)'s last term, in nodal form), shifted by the state's
  // augmented-Lagrangian multipliers.
  Pressures penalty_pressures(const Displacements& u, const RunState& state) const;
  // Contact forces on every body from pressures: f_slave = -Gs^T z, f_master = Gm^T z; with tangential
  // multipliers q (friction pairs; pair.hpp) also f_slave -= Ts^T q, f_master += Tm^T q.
  Displacements loads_from_pressures(const Pressures& z, const Pressures* q = nullptr) const;
  // Contact forces from the penalty pressures of u (they go to *pressures if given).
  Displacements contact_loads(const Displacements& u, const RunState& state, Pressures* pressures = nullptr) const;

  // Body a's normal displacements at its contact zones' nodes (u_an of the paper's stopping test), stacked over
  // the pairs it belongs to: for a slave the displacement of the contact node along its normal; for a master
  // the mortar projection of its displacement onto the slave node, along the master's normal (-n).
  Eigen::VectorXd zone_normals(size_t a, const Eigen::VectorXd& u_a) const;

  // Each body solved under its own loads at load point `at` plus the given loads, in parallel.
  Displacements solve_bodies(const Displacements& loads, const fem::LoadPoint& at) const;

  // The "elastic layer" initial guess (paper section 4; docs/algorithm.md, "Initial guess") at load point `at`.
  Displacements elastic_layer_guess(const fem::LoadPoint& at) const;

  // Per-iteration report for pressures z and nodal gaps g (per pair, per row); `previous_active` holds each
  // pair's active flags of the previous report and is updated. The other forms take the gaps of displacements
  // u, and (penalty) the pressures too.
  IterationReport report_gaps(int iteration, const Pressures& z, const Pressures& nodal_gaps,
                              std::vector<std::vector<char>>& previous_active) const;
  IterationReport report(int iteration, const Displacements& u, const Pressures& z,
                         std::vector<std::vector<char>>& previous_active) const {
    return report_gaps(iteration, z, nodal_gaps(u), previous_active);
  }
  IterationReport report(int iteration, const Displacements& u, const RunState& state,
                         std::vector<std::vector<char>>& previous_active) const {
    return report(iteration, u, penalty_pressures(u, state), previous_active);
  }
  // Adds the friction pairs' tangential tractions, stick flags and tangential forces to a report.
  void report_friction(const Pressures& z, const Pressures& q, IterationReport& report) const;
  // The nodal gaps (weighted gap / D) of displacements u.
  Pressures nodal_gaps(const Displacements& u) const;

  // Final fields (one Step), the bodies' stresses and reactions computed on the runner the system was built with,
  // for displacements u with pressures z (the penalty form computes z from u) under the loads of the state's load
  // point, and the floating bodies' rigid-mode amplitudes if known.
  Step fields(const Displacements& u, const Pressures& z, int iteration, const RunState& state,
              const std::vector<Eigen::VectorXd>* rigid_amplitudes = nullptr, const Pressures* q = nullptr) const;
  Step fields(const Displacements& u, int iteration, const RunState& state) const {
    return fields(u, penalty_pressures(u, state), iteration, state);
  }

 private:
  // fields() in phases (system_fields.cpp): the bodies' stresses and support reactions (on their owners), one
  // body's field, one pair's field.
  void stresses_and_reactions(const Displacements& u, const Displacements& loads, const fem::LoadPoint& at,
                              std::vector<fem::StressFields>& stress, std::vector<Eigen::VectorXd>& reaction) const;
  BodyField body_field(size_t a, const Eigen::VectorXd& u, fem::StressFields stress, const Eigen::VectorXd& reaction,
                       const Eigen::VectorXd* rigid_amplitudes) const;
  PairField pair_field(size_t k, const Displacements& u, const Eigen::VectorXd& z, const Eigen::VectorXd* q) const;
  // Status-5 nodes (carried by another pair of their group) take the carrying pair's values (system_fields.cpp).
  void share_carried_values(std::vector<PairField>& pairs) const;

  void discretize_pairs();
  void check_some_row();
  // Full dofs of body a that some pair's operators act on (empty unless Factorization::interface).
  std::vector<int> interface_dofs(size_t a) const;
  // Whether body a may float (held by its contacts): in a pair, and a method that handles it.
  bool may_float(size_t a) const;
  // Body a's solver: assembled and factorised (local), or only its constraints (owned by another process).
  std::unique_ptr<fem::BodySolver> make_body(size_t a, bool local, const std::function<bool()>& stop = {}) const;
  // Builds the bodies `todo` (in parallel), then collects their errors and factorisation times.
  void build_bodies(const std::vector<size_t>& todo, const std::function<bool()>& stop);
  parallel::BodyShare body_outcome_share();

  const Problem& problem_;
  Factorization factorization_ = Factorization::plain;
  parallel::TaskRunner& runner_;  // the one it was built with (fields() runs per-body work on it)
  std::vector<std::unique_ptr<fem::BodySolver>> bodies_;
  std::vector<mortar::PairDiscretization> pairs_;
  std::vector<mortar::PenaltyChoice> penalties_;
  std::vector<std::vector<size_t>> pairs_of_body_;  // pairs_of(a)
  std::string error_;
  bool cancelled_ = false;
  double setup_seconds_ = 0.0, factorization_seconds_ = 0.0;
};

// How one full vector per body (displacements, loads) moves from its owner to the other processes.
parallel::BodyShare share_vectors(std::vector<Eigen::VectorXd>& per_body);

// Relative norm used by both stopping tests: ||a - b|| / max(||a||, ||b||), 0 when both vanish.
double relative_change(const Eigen::VectorXd& now, const Eigen::VectorXd& before);

}  // namespace contact::ddm
