// The friction and FETI policy: the tuning of the chain a frictional load step goes through, named once. The solvers
// read these values as PERMON's read their options; each field says its rule in a line, and the section of
// docs/algorithm.md (or docs/friction.md, docs/friction-solvers.md) that justifies it. The runs that pin them are the
// golden record (tests/data/golden_record.json, scripts/golden_record.py): a retuning moves its counts, and its test
// fails until the record is written again, so that the move shows in review.
//
// The recovery chain of a frictional load step, in order:
//   1. The direct interface solver's friction Newton (ddm/interface/friction_direct.cpp on linalg/friction_newton:
//      a globalised semismooth Newton, whose own safeguards - its watchdog and merit growth - are the Newton's and
//      stay in friction_newton.cpp) runs with a budget of DirectNewton::budget steps, and stops sooner where it
//      stalls (DirectNewton::stall_steps).
//   2. Where it has not settled within that budget, the iterative solver (FETI, ddm/interface/feti_friction.cpp)
//      takes the same step over, without a preconditioner (interface_newton.cpp).
//   3. FETI solves Coulomb by an outer fixed point on the slip bounds (CoulombOuter), each Tresca problem by SMALBE
//      with inner MPRGP (Smalbe). Its retreats, in order: the tied bounds (+inf) when the warm start's bounds hold
//      no floating body; the plain update mu z when the Anderson-mixed bounds fail a solve.
//   4. Inside SMALBE: the settled face solved by CG with its own projector (smalbe_face.cpp; Smalbe::face_*),
//      and the penalty rho raised where the multiplier updates crawl or stall (Smalbe::rho_*); the equality
//      violation's stagnation ends the solve as "the contacts do not hold every floating body".
//   5. A step that still does not converge is cut (load_steps.cpp): its increment halved, at most LoadStepCuts::
//      max_cuts times, the sub-steps solved and accepted in turn; not cut when it starts from rest with every joint
//      closed (the same problem scaled).
#pragma once

namespace contact::ddm::policy {

// 1-2. The direct solver's friction Newton before the iterative solver takes the step over.
struct DirectNewton {
  // Steps of the direct friction Newton before the take-over: where it settles it does so within tens of steps (51
  // at the most measured); past that it crawls by damped steps of one sparse LU each (docs/friction-solvers.md).
  int budget = 100;
  // ...and it is handed over sooner where it stalls: the lowest merit of its last `stall_steps` accepted steps fell
  // by less than `stall_fall` of the lowest before them (linalg/friction_newton.hpp). Of the 568 Newton runs that
  // settle in the friction tests one meets it (27 accepted steps, its merit flat over steps 3-11; the iterative
  // solver then gives the same answer), none with a window of 12; the 8 x 8 wall at H/V 0.5 on 16 cells a brick
  // crawled 21 steps (95 solves, 3.5 s) from a merit of 953 to 200 before, and is handed over after 9 (32 solves).
  int stall_steps = 8;
  double stall_fall = 0.5;
};

// 3. FETI's Coulomb outer iteration on the slip bounds (docs/algorithm.md, "Friction in the iterative solver").
struct CoulombOuter {
  // The outer iteration stops when the bounds moved by less than this times the tolerance (and the Coulomb
  // complementarity is below that too), or the bounds have settled.
  double stop_factor = 1e3;
  // The first Tresca solve's tolerance: its bounds are wrong by far more than any finer answer would fix.
  double first_tolerance = 1e-3;
  // Each later Tresca solve to this fraction of the bounds' last change...
  double tolerance_per_change = 0.01;
  // ...never below this many times the tolerance (a warm start's projected gradient meets its rounding floor there).
  double tolerance_floor = 10;
  // The bounds are Anderson-mixed over this many past updates (linalg/anderson.hpp).
  int anderson_depth = 5;
  // Settled: the bounds stopped moving in this many outer iterations at the finest inner tolerance...
  int settled_iterations = 2;
  // ...and a settled complementarity above this is a slip against its friction force, not an answer.
  double settled_complementarity_limit = 1e-5;
};

// 3-4. SMALBE with inner MPRGP (docs/algorithm.md, "The interface solvers" and "Friction in the iterative solver").
struct Smalbe {
  // The inner solves stop at min(M ||Q x||, eta) with eta this fraction of the gradient's scale...
  double eta = 0.1;
  // ...and never below this fraction of the solve's tolerance.
  double inner_floor = 0.1;
  // MPRGP's step length alpha_bar = step / (margin ||A||): the power method underestimates ||A|| a little.
  double step = 1.9;
  double norm_margin = 1.05;
  // A settled face is solved on its own at most this many times a solve (a face that was not the answer's costs
  // its products).
  int face_attempts = 2;
  // Its CG runs to this fraction of the tolerance where that tolerance is the finest the solve is asked for (within
  // face_finest_factor of it), else to the tolerance itself.
  double face_target_finest = 0.1;
  double face_finest_factor = 10;
  // rho is raised (x rho_raise) once the equality violation fell by less than rho_crawl in each of the last three
  // updates, up to rho_cap ||P H P||; past that only where the updates stalled (fell by less than rho_stall in each
  // of the last three) with cheap inner solves (at most rho_stall_inner iterations), up to rho_stall_cap ||P H P||.
  double rho_raise = 10;
  double rho_crawl = 0.5;
  double rho_cap = 10;
  double rho_stall = 0.95;
  long rho_stall_inner = 50;
  double rho_stall_cap = 1e6;
  // A violation that fell by less than this factor's complement (0.1 %) in each of the last three updates is frozen:
  // the box holds the multipliers where they are, whatever nu does (bounds that admit no equilibrium: the
  // Anderson-extrapolated slip bounds of a wall near its limit), so rho is raised as for a stall whatever the inner
  // solves cost, and the stagnation below ends the solve within a few updates (it ran 2,000 updates, 11.5 s, on the
  // 8 x 8 wall's collapse trials before; docs/friction-solvers.md).
  double rho_frozen = 0.999;
  // Stagnation: over at least stagnation_window updates the violation fell by less than stagnation_fall in the last
  // three, with rho at stagnation_rho ||P H P||: no admissible pressures balance some floating body.
  int stagnation_window = 8;
  double stagnation_fall = 0.5;
  double stagnation_rho = 1e6;
};

// 5. Load-step cuts (docs/friction.md, "Near the limit: cut steps and indeterminate slip").
struct LoadStepCuts {
  // A frictional step that does not converge has its increment halved at most this many times (down to 1/32).
  int max_cuts = 5;
};

struct FrictionPolicy {
  DirectNewton direct;
  CoulombOuter coulomb;
  Smalbe smalbe;
  LoadStepCuts cuts;
};

inline constexpr FrictionPolicy kFrictionPolicy{};

}  // namespace contact::ddm::policy
