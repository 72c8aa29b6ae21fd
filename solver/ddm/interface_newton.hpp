// Interface Newton (see interface_newton.cpp): the compliance set-up is kept, so that the augmented-Lagrangian
// updates, which only shift the gaps, re-solve the small interface problem without touching the bodies again.
#pragma once

#include "method.hpp"

namespace contact::ddm {

class InterfaceNewton {
 public:
  // Computes every body's contact-zone compliance and free response (bodies in parallel through `runner`).
  InterfaceNewton(const ContactSystem& system, TaskRunner& runner);
  // Solves the interface problem on the pairs' current effective gaps and recovers the fields (one solve per
  // body); solves_per_body of the outcome counts that solve only.
  MethodOutcome solve(const SolverSettings& settings, RunContext& context) const;
  // Back-substitutions per body spent by the constructor (zone columns + the free response).
  int setup_solves() const { return setup_solves_; }

 private:
  struct BodyZone {
    std::vector<int> dofs;          // zone dofs (sorted)
    Eigen::MatrixXd S;              // compliance on the zone dofs
    Eigen::VectorXd free_zone;      // free response on the zone dofs
    Eigen::SparseMatrix<double> Q;  // n_points x zone dofs (signed contact operator rows)
  };
  const ContactSystem& system_;
  std::vector<Eigen::Index> offset_;
  std::vector<BodyZone> zones_;
  Eigen::VectorXd weight_, theta_, free_jump_;
  Eigen::MatrixXd M_;
  int setup_solves_ = 0;
};

}  // namespace contact::ddm
