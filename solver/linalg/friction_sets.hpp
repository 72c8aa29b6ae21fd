// The stick and slip sets of 2-D frictional contact and the linear system they give: the primal-dual active set
// (semismooth Newton) of Hueber, Stadler & Wohlmuth for Coulomb and Tresca friction, in the form both the interface
// solver (ddm/interface/friction_direct.hpp) and the monolithic reference use; the Newton iteration on them is
// friction_newton.hpp. Pure linear algebra.
//
// Multipliers lambda = [z; q]: normal pressures z_i >= 0 and tangential multipliers q_t, each q_t paired with one
// normal row i(t) (the same contact node). h(lambda) are the conjugate quantities: the weighted normal gaps and the
// weighted tangential slips w_t (of this load step). The conditions per node, with the bound b_t = mu z_i (Coulomb)
// or g (Tresca):
//   z >= 0, h_n >= 0, z h_n = 0;   |q| <= b;   |q| < b => w = 0;   |q| = b => w = -beta q, beta >= 0,
// i.e. q = proj_[-b, b](q - c w) for any c > 0 (friction opposes the slip). The semismooth Newton step for this
// complementarity function in 2-D (one tangent) predicts from the current iterate, with c_j the scaling of
// unknown j (its own compliance's inverse):
//   normal i active  iff  z_i - c_i h_i > 0  (else z_i = 0 and, under Coulomb, q_t = 0: open);
//   row t sticks     iff  |q_t - c_t w_t| <= b_t,  with b_t = mu max(0, z_i - c_i h_i) (Coulomb) or g (Tresca);
//   otherwise it slips in the direction s_t = sign(q_t - c_t w_t):  q_t = s_t b_t.
// On the predicted sets the conditions are linear: h_i = 0 (active normals), w_t = 0 (stick), q_t = s_t mu z_i or
// s_t g (slip). So lambda = P y + lambda0 with y the free multipliers (active z, sticking q; a slipping q follows its
// z), and the rows whose h must vanish are exactly the unknowns y stand for: a square system. The sets repeat at
// the solution, where the step is exact (piecewise linear map). For Coulomb the system is non-symmetric (the slip
// rows couple q to z); the non-symmetry stays in this small system.
//
// Tresca's bound holds on the whole contact boundary, open or not (the classical given-friction problem): the
// problem is then the convex QP  min 1/2 lambda^T F lambda + g^T lambda  over z >= 0, |q| <= g, whose solution is
// unique. A bound that vanished where the node opens would make it discontinuous, with no solution in general (an
// edge node that the friction traction lifts: in contact, the traction opens it; open, it penetrates).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace contact::linalg {

struct FrictionRow {
  Eigen::Index normal = 0;      // index of z_i in lambda
  Eigen::Index tangential = 0;  // index of q_t in lambda
  bool coulomb = true;
  double mu = 0.0;     // Coulomb
  double bound = 0.0;  // Tresca
};

// The state of one friction row: open (no bound, q = 0: a Coulomb row whose normal row is inactive), stick or slip.
enum class FrictionState : char { open = 0, stick = 1, slip = 2 };

struct FrictionSets {
  std::vector<char> active;          // per unknown of lambda: 1 for an active normal row (tangential rows: unused)
  std::vector<FrictionState> state;  // per friction row
  std::vector<int> sign;             // per friction row: s_t where it slips
  bool operator==(const FrictionSets& o) const { return active == o.active && state == o.state && sign == o.sign; }
  int changes(const FrictionSets& o) const;  // unknowns whose state differs
};

// The sets predicted from lambda, h and the scaling c (all of the size of lambda). `is_tangential[j]` marks the
// tangential unknowns.
FrictionSets predict_friction_sets(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                                   const std::vector<FrictionRow>& rows, const std::vector<char>& is_tangential);

// "Every node in contact sticks": each friction row sticks where its normal row is active (Tresca: everywhere, its
// bound holds open or not) and is open otherwise. The tied problem under the loads is well posed (friction holds the
// floating bodies), which makes it the start where nothing better is known and the retreat from a singular set.
void stick_where_in_contact(FrictionSets& sets, const std::vector<FrictionRow>& rows);

// lambda = P y + lambda0 on the sets; `rows` lists, for each column of P, the unknown whose h must vanish.
struct FrictionParametrization {
  std::vector<Eigen::Index> rows;
  Eigen::SparseMatrix<double> P;  // size(lambda) x rows.size()
  Eigen::VectorXd lambda0;
};
FrictionParametrization parametrize(const FrictionSets& sets, const std::vector<FrictionRow>& rows,
                                    const std::vector<char>& is_tangential);

// Which Coulomb bound the complementarity function C takes: mu z at the current normal multiplier (the residual the
// solvers report) or mu max(0, z - c h_n) at the normal trial (what a set's slip rows impose: the Newton's merit).
enum class CoulombBound { current, trial };

// ||C(lambda)||^2 with the normal part z - max(0, z - c h) and the tangential part q - proj_[-b,b](q - c w).
double complementarity_squared(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                               const std::vector<FrictionRow>& rows, const std::vector<char>& is_tangential,
                               CoulombBound bound);

// ||C(lambda)|| / max(||lambda||, tiny): normal C_i = z_i - max(0, z_i - c_i h_i), tangential
// C_t = q_t - proj_[-b,b](q_t - c_t w_t) with b from the current z.
double friction_complementarity(const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, const Eigen::VectorXd& c,
                                const std::vector<FrictionRow>& rows, const std::vector<char>& is_tangential);

// Where the friction rows are: a mask of the tangential unknowns.
std::vector<char> tangential_mask(Eigen::Index size, const std::vector<FrictionRow>& rows);

}  // namespace contact::linalg
