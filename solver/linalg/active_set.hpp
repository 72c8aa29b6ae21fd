// A linear complementarity problem in nodal pressures z, solved by a primal-dual active set on sparse matrices:
//
//   h = g + H z + G^T alpha,   z >= 0,  h >= 0,  z_j h_j = 0  for every unknown j,   G z = e,
//
// with H symmetric positive definite (on ker G where there are equalities), g the gaps at z = 0, and optional
// equalities G z = e with multipliers alpha (in the contact problem: the equilibrium of the floating bodies, FETI's
// coarse problem). It is the KKT system of the convex QP  min 1/2 z^T H z + g^T z  over z >= 0 with G z = e.
//
// Solved by the primal-dual active set strategy (Hintermueller, Ito & Kunisch 2002), a semismooth Newton method
// for the complementarity function
//   C_j(z) = z_j - max(0, z_j - c_j h_j / D_j),   c_j = D_j / H_jj  (the node's own stiffness: c h / D = h / H_jj
//   is the pressure that would close the gap h_j alone),
// predicting the active set A = {j : z_j - h_j / H_jj > 0}, then solving h_A = 0 with z = 0 off A (with G: the
// saddle-point system of A, sparse, by LU): the map is piecewise linear, so the step on the
// right active set is exact, and the iteration stops when the set repeats. Should the sets ever cycle, a primal
// active-set method for the QP (Lawson & Hanson's NNLS generalised; without G only) takes over: it ends in
// finitely many steps.
//
// Every matrix is sparse: H_AA is factorised by CHOLMOD (supernodal) at every step (with G: the saddle system by
// UMFPACK; no block is dense in the number of floating bodies), so a problem whose H couples
// each unknown to a few others (the interface of many bodies) costs what its sparse factor costs, while a dense H
// (two bodies with one contact zone) costs what a dense Cholesky costs. Pure linear algebra: nothing here knows
// of bodies or meshes.
#pragma once

#include "../common/solve_report.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace contact::linalg {

using SparseMatrix = Eigen::SparseMatrix<double>;

struct ActiveSetStep {
  int step = 0;                  // 1-based
  int active = 0;                // |A|
  int changes = 0;               // nodes that entered or left A in this step
  double complementarity = 0.0;  // ||C(z)|| / max(||z||, tiny) after the step
};

// Equality constraints G z = e with multipliers alpha (G: r x n, sparse). Empty: none.
struct Equalities {
  SparseMatrix G;
  Eigen::VectorXd e;
  bool empty() const { return G.rows() == 0; }
};

// A bound-constrained QP's solution as its solvers return it (the primal-dual active set here, every interface
// solver of ddm/interface/): the multipliers, the equalities' multipliers and the gradient, and how the solve
// stopped, in the solver's one vocabulary (common/solve_report.hpp).
struct QpSolution {
  Eigen::VectorXd z;
  Eigen::VectorXd alpha;      // the equalities' multipliers (empty without)
  Eigen::VectorXd h;          // g + H z + G^T alpha
  long inner_iterations = 0;  // iterative solvers: products with H (0 for the direct one)
  bool used_fallback = false;
  // The equalities could not be met by the active nodes (a floating body held by nothing): the rows of G that
  // the active set leaves unrestrained (empty otherwise).
  std::vector<Eigen::Index> unrestrained;
  // iterations: active-set steps (direct) or outer iterations (iterative solvers); the stop: converged,
  // max_iterations, singular (the active set leaves rows of G unrestrained) or cancelled; the message says more.
  SolveReport report;
};

using StepCallback = std::function<bool(const Eigen::VectorXd& z, const Eigen::VectorXd& h, const ActiveSetStep&)>;

// on_step is called after every step with the current z and h; returning true stops (cancels), as every stop
// callback of the solver returns. `z0` (optional, same
// size as g) gives the first active set {z0 - h(z0) / H_jj > 0} ({z0 > 0} with equalities: a floating body's
// own position is not known before the solve); without it, the nodes where g < 0, or every node with equalities.
QpSolution solve_active_set(const SparseMatrix& H, const Eigen::VectorXd& g, int max_steps, const StepCallback& on_step,
                            const Eigen::VectorXd* z0 = nullptr, const Equalities& equalities = {});

// The QP method on its own (for the fallback and for tests): min 1/2 z^T H z + g^T z, z >= 0.
Eigen::VectorXd solve_nonnegative_qp(const SparseMatrix& H, const Eigen::VectorXd& g, int max_steps = 0);

// The unknowns a coarser multiplier space keeps: every other one of each line (line[j], consecutive per line), its
// first and last always.
std::vector<Eigen::Index> coarse_unknowns(const std::vector<int>& line);

// A first guess for the active set from the same problem on coarser multiplier spaces (nested iteration): the
// unknowns lie on lines (line[j], consecutive and ordered by position[j] along each line, e.g. the contact nodes
// of each pair along its slave edge); every other one is kept per line (the ends always), the rest interpolated
// linearly in position (P), and the coarse problem z_c >= 0, P^T g + (P^T H P) z_c (+ G^T alpha) >= 0,
// (G P) z_c = e is solved the same way, recursively down to `coarsest` unknowns. Since P >= 0, a non-negative
// coarse solution prolongs to a non-negative z. Returns P z_c. Where the solution's active set is a contiguous
// zone whose edge moves a few nodes per step from a cruder guess, this keeps the number of fine steps
// independent of the mesh size. `levels` receives the size of every coarse problem solved and its active-set
// steps (finest first).
Eigen::VectorXd nested_initial_guess(const SparseMatrix& H, const Eigen::VectorXd& g, const std::vector<int>& line,
                                     const Eigen::VectorXd& position, const Equalities& equalities = {},
                                     std::vector<std::pair<Eigen::Index, int>>* levels = nullptr,
                                     Eigen::Index coarsest = 32);

}  // namespace contact::linalg
