#include "feti.hpp"

#include "smalbe.hpp"

namespace contact::ddm {

linalg::QpSolution FetiSolver::solve(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context) {
  if (qp.problem.size() > qp.problem.normal_size()) return solve_friction(qp, z0, context);
  linalg::QpSolution out;
  Smalbe smalbe(qp, settings_, context);
  if (!smalbe.prepare(out)) return out;
  const Smalbe::Bounds bounds{Eigen::VectorXd::Zero(qp.problem.size()), Eigen::VectorXd()};  // z >= 0
  Smalbe::Solve how;
  how.tolerance = settings_.tolerance;
  smalbe.solve(bounds, z0, how, out);
  return out;
}

}  // namespace contact::ddm
