// Interface Newton (see interface_newton.cpp). The object keeps what it computed of each body's contact-zone
// compliance, so that the augmented-Lagrangian updates, which only shift the gaps, re-solve the small interface
// problem with few or no new back-substitutions.
#pragma once

#include "method.hpp"

namespace contact::ddm {

class InterfaceNewton {
 public:
  // Each body's free response and contact-zone operators (bodies in parallel through `runner`). Compliance
  // columns are computed on demand by solve().
  InterfaceNewton(const ContactSystem& system, TaskRunner& runner);
  // Solves the interface problem on the pairs' current effective gaps and recovers the fields (one solve per
  // body). solves_per_body of the outcome counts the back-substitutions this call added.
  MethodOutcome solve(const SolverSettings& settings, RunContext& context);
  // Back-substitutions per body so far (the largest over the bodies).
  int solves() const { return solves_; }

 private:
  struct BodyZone {
    std::vector<int> dofs;          // zone dofs (sorted)
    Eigen::MatrixXd S;              // compliance on the zone dofs; only columns with have[j] are computed
    std::vector<char> have;
    Eigen::VectorXd free_zone;      // free response on the zone dofs
    Eigen::SparseMatrix<double, Eigen::RowMajor> Q;  // n_points x zone dofs (signed contact operator rows)
    int solves = 0;
  };
  // Computes the compliance columns that the loads at the candidate points need.
  void ensure_columns(const std::vector<char>& candidate, TaskRunner& runner);

  const ContactSystem& system_;
  std::vector<Eigen::Index> offset_;
  std::vector<BodyZone> zones_;
  Eigen::VectorXd weight_, theta_, free_jump_;
  int solves_ = 0;
};

}  // namespace contact::ddm
