#include "sparse_direct.hpp"

#include <sstream>

namespace contact::ddm {

linalg::QpSolution SparseDirectSolver::solve(const InterfaceQp& qp, const Eigen::VectorXd* z0,
                                             InterfaceSolveContext& context) {
  const Eigen::Index m = qp.problem.size();
  SparseMatrix H = F_.of(qp.problem);
  // (m == 0: no contact row at all, every slave node a crosspoint; Eigen's maxCoeff is undefined on an empty vector.)
  const bool penalised = m > 0 && qp.penalty.size() == m && qp.penalty.cwiseAbs().maxCoeff() > 0;
  if (penalised) {
    SparseMatrix D(m, m);
    D.reserve(Eigen::VectorXi::Constant(m, 1));
    for (Eigen::Index i = 0; i < m; ++i) D.insert(i, i) = qp.penalty[i];
    H += D;
  }
  Eigen::VectorXd guess;
  // Exact contact: every solve (also a new load step) starts from nested coarse solves, which place the contact
  // zone's edge to within a node or two; the previous step's active set would move it a node or two per step.
  // Under the penalty and the augmented Lagrangian the previous pressures stay the start (an update shifts them
  // little).
  const bool exact = !penalised;
  if (!z0 || z0->size() != m || exact) {
    std::vector<std::pair<Eigen::Index, int>> levels;
    guess = linalg::nested_initial_guess(H, qp.g, qp.line, qp.position, qp.equilibrium, &levels);
    if (!levels.empty()) {
      std::ostringstream os;
      os << "first active set from coarse solves:";
      for (const auto& [size, steps] : levels) os << " " << size << " nodes/" << steps << " steps";
      context.note = os.str();
    }
    z0 = &guess;
  }
  const bool useful = z0->size() == m && m > 0 && z0->cwiseAbs().maxCoeff() > 0;
  return linalg::solve_active_set(H, qp.g, context.max_steps, context.on_step, useful ? z0 : nullptr, qp.equilibrium);
}

}  // namespace contact::ddm
