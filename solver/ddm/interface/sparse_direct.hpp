// The direct interface solver: the primal-dual active set (linalg/active_set.hpp) on F + diag(penalty) assembled
// as a sparse matrix from the bodies' blocks. Each step factorises the active block with CHOLMOD: for a wall of
// bricks a sparse factor (cost growing like the number of contact nodes to the power 1.5 in a 2-D arrangement), for
// two bodies sharing one contact zone a dense one, as before. Without a warm start the first active set comes from
// nested coarse solves along each pair's slave edge, which keeps the number of steps independent of the mesh.
#pragma once

#include "interface_solver.hpp"

namespace contact::ddm {

class SparseDirectSolver final : public InterfaceSolver {
 public:
  const char* name() const override { return "direct"; }
  linalg::QpSolution solve(const InterfaceQp& qp, const Eigen::VectorXd* z0, InterfaceSolveContext& context) override;

 private:
  AssembledCompliance F_;
};

}  // namespace contact::ddm
