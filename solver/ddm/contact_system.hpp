// All bodies and contact pairs of a problem on fixed meshes: each body's factorised solver and each pair's
// discretisation, plus the evaluations every method needs (contact forces, contact-zone normal displacements,
// per-iteration reports, final fields). Rebuilt when a mesh changes.
#pragma once

#include "../contact/pair.hpp"
#include "../fem/body_solver.hpp"
#include "../problem.hpp"
#include "../result.hpp"
#include "task_runner.hpp"

#include <memory>
#include <string>
#include <vector>

namespace contact::ddm {

using Displacements = std::vector<Eigen::VectorXd>;  // one full dof vector per body

class ContactSystem {
 public:
  // Assembles every body and (if `factorize`) factorises them, in parallel through `runner`; then
  // discretises every pair. Check ok() / error().
  ContactSystem(const Problem& problem, TaskRunner& runner, bool factorize = true);

  // After the meshes of the bodies flagged in `changed` were refined (in the Problem this system refers to):
  // reassembles and refactorises those bodies only (an unchanged body keeps its factorisation) and rediscretises
  // every pair. Multipliers are dropped. Check ok() afterwards.
  void rebuild(const std::vector<char>& changed, TaskRunner& runner);

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  // Assembly and factorisation seconds of all bodies built so far (summed over bodies).
  double total_factorization_seconds() const { return factorization_seconds_; }

  const Problem& problem() const { return problem_; }
  size_t n_bodies() const { return bodies_.size(); }
  const fem::BodySolver& body(size_t a) const { return *bodies_[a]; }
  const std::vector<interface::PairDiscretization>& pairs() const { return pairs_; }
  const std::vector<interface::PenaltyChoice>& penalties() const { return penalties_; }
  double setup_seconds() const { return setup_seconds_; }
  double factorization_seconds() const { return factorization_seconds_; }  // summed over bodies

  // Augmented-Lagrangian multipliers of pair k at its Gauss points (an empty vector: none).
  void set_multipliers(size_t k, Eigen::VectorXd gauss) { pairs_[k].multiplier = std::move(gauss); }

  // Contact forces on every body from the penalty pressures of displacements u (paper (16)'s last term);
  // the pressures at each pair's Gauss points go to *pressures if given.
  Displacements contact_loads(const Displacements& u, std::vector<Eigen::VectorXd>* pressures = nullptr) const;
  // Same from given Gauss-point pressures.
  Displacements loads_from_pressures(const std::vector<Eigen::VectorXd>& pressures) const;

  // Body a's normal displacements at the FE nodes of its contact zones (u_an of the paper's stopping test),
  // stacked over the pairs it belongs to.
  Eigen::VectorXd zone_normals(size_t a, const Eigen::VectorXd& u_a) const;

  // Each body solved with the given loads, in parallel.
  Displacements solve_bodies(const Displacements& loads, TaskRunner& runner) const;

  // The "elastic layer" initial guess (paper section 4, ALGORITHM.md section 5).
  Displacements elastic_layer_guess(TaskRunner& runner) const;

  // Per-iteration report for displacements u; `previous_active` holds each pair's active flags at the Gauss
  // points of the previous report and is updated.
  IterationReport report(int iteration, const Displacements& u, std::vector<std::vector<char>>& previous_active) const;

  // Final fields (one Step).
  Step fields(const Displacements& u, int iteration) const;

 private:
  const Problem& problem_;
  bool factorize_ = true;
  std::vector<std::unique_ptr<fem::BodySolver>> bodies_;
  std::vector<interface::PairDiscretization> pairs_;
  std::vector<interface::PenaltyChoice> penalties_;
  std::string error_;
  double setup_seconds_ = 0.0, factorization_seconds_ = 0.0;
};

// Relative norm used by both stopping tests: ||a - b|| / max(||a||, ||b||), 0 when both vanish.
double relative_change(const Eigen::VectorXd& now, const Eigen::VectorXd& before);

}  // namespace contact::ddm
