// The monolithic reference's second way to frictional contact: an augmented Lagrangian on the stacked system
// (Simo & Laursen 1992; Alart & Curnier's multiplier form), for the steps its semismooth Newton on the stick and slip
// sets does not settle (near the limit it cycles between sets whose saddle-point systems are singular: a brick
// whose every contact node slips).
//
// With the multipliers lambda (normal z, tangential q) and the slip bounds b held, each row r's term is the Moreau
// envelope of its constraint, mu*_r = proj_C(lambda_r - rho_r g_r(x)) with C = [0, inf) for a normal row and
// [-b, b] for a tangential one (friction opposes the slip: q = -b sign(w) where it slips), and x minimises the
// convex, piecewise quadratic
//   L(x) = 1/2 x^T K x - b^T x + sum_r ( -mu*_r g_r(x) - (mu*_r - lambda_r)^2 / (2 rho_r) ),
// whose gradient is K x - b - B^T mu*(x): Newton steps on K + B^T diag(rho on the rows inside C) B (CHOLMOD) with an
// Armijo line search on L, which converge for any start (the matrix regularised by 1e-10 of each unknown's own
// stiffness along a brick that slides at both its joints: a flat direction of L). Then lambda <- mu*(x) and, for
// Coulomb, b <- mu z: at the fixed point lambda = proj_C(lambda - rho g) is exactly the complementarity of the
// contact and friction conditions. rho is the rows' own stiffness scale c (ddm/monolithic.cpp's active-set
// prediction) times `boost`: a stiffer augmentation converges in fewer updates at a worse-conditioned matrix.
#pragma once

#include "monolithic_system.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

namespace contact::ddm::monolithic {

struct AlmSettings {
  int max_updates = 500;  // multiplier updates
  // The friction complementarity (linalg/friction_sets.hpp) of the answer: its sets are then the solution's, on
  // which the Newton's step (ddm/monolithic.cpp) is exact.
  double tolerance = 1e-9;
  double boost = 1e3;  // rho = boost c
  // Below this complementarity each Coulomb iteration's answer is offered to `confirm` (the caller's Newton on the
  // sets it predicts): the sets are usually right long before the multipliers reach the tolerance, and near the
  // limit the multipliers may never reach it (a collapse trial of the 4 x 4 wall at 0.5905 of its 0.600 stalled at
  // 4e-8 after 500 updates; offered from 1e-4 with ten Newton steps, its sets were confirmed and the bracket closed
  // at 0.5996, where from 1e-6 with three it stayed at 0.5902).
  double confirm_below = 1e-4;
};

struct AlmOutcome {
  bool converged = false;
  bool cancelled = false;
  int updates = 0;       // multiplier updates
  int newton_steps = 0;  // factorisations
  Eigen::VectorXd x, lambda, h;
  double complementarity = 0.0;
  bool confirmed = false;  // converged because `confirm` accepted the answer's sets
  std::string failure;     // why it stopped unconverged
};

// After each update: its number, the iterate and its complementarity; true stops the solve (cancelled).
using AlmCallback = std::function<bool(int update, const Eigen::VectorXd& x, const Eigen::VectorXd& lambda,
                                       const Eigen::VectorXd& h, double complementarity)>;

// Whether the caller takes an answer as converged (it solved the sets the answer predicts exactly).
using AlmConfirm = std::function<bool(const AlmOutcome& answer)>;

// From x0 and lambda0 (either may be empty: zero; without lambda0 the first update holds every contact node by
// unbounded friction, the tied problem, which is well posed where Coulomb bounds of zero would let every floating
// body slide). `mask` marks the tangential rows, `c` each row's scale (prediction and rho). `cancelled` is asked
// before every Newton step (one factorisation: a cancel stops the solve within one).
AlmOutcome solve_by_augmented_lagrangian(const Stacked& s, const std::vector<char>& mask, const Eigen::VectorXd& c,
                                         const Eigen::VectorXd& x0, const Eigen::VectorXd& lambda0,
                                         const AlmSettings& settings, const AlmCallback& after_update,
                                         const AlmConfirm& confirm, const std::function<bool()>& cancelled);

}  // namespace contact::ddm::monolithic
