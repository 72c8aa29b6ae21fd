// Reference solver: the same discrete contact problem as the DDM, all bodies in one system. Unknowns x = every
// body's free dofs (u_a = T_a x_a + g_a); the weighted gaps are affine, g(x) = g0 + B x (B and g0 from each
// pair's Gs, Gm and the prescribed values).
//  * penalty: minimise  1/2 x^T K x - b^T x + sum_r 1 / (2 theta D_r) min(0, g_r(x))^2  (convex, piecewise
//    quadratic) by semismooth Newton steps with a backtracking line search; each step factorises
//    K + B^T W_A B with CHOLMOD.
//  * exact: the primal-dual active set on the whole system: on the active set A the saddle-point system
//    [K  -B_A^T; B_A  0] [x; z_A] = [b; -g0_A] (equilibrium with the contact forces, and g_A = 0) is solved by a
//    sparse LU factorisation (Eigen's SparseLU), and A is predicted as {z - c g / area > 0}. With friction the
//    rows of B include each friction pair's tangential rows (-Ts, +Tm; the slip of the step g0 - w_origin), and
//    the same stick and slip sets as the interface solver's (linalg/friction_sets.hpp) give lambda = P y +
//    lambda0: [K  -B^T P; R B  0] [x; y] = [b + B^T lambda0; -R g0]. Slow for large problems (an unsymmetric
//    factorisation per step): a reference, not a production method. Near the limit that Newton cycles (sets whose
//    systems are singular: a brick that slips at every contact node); a step it does not settle is solved again
//    by an augmented Lagrangian on the same stacked system (monolithic_friction.hpp) and its answer's sets
//    confirmed by the Newton.
// Both are independent of the interface machinery (Schur complements, dense active-set solves) that
// interface Newton uses, which is what makes them a check on it.
#include "method.hpp"
#include "monolithic_friction.hpp"
#include "monolithic_system.hpp"

#include "../linalg/friction_newton.hpp"
#include "friction_policy.hpp"
#include "friction_rows.hpp"
#include "friction_statics.hpp"
#include "../linalg/friction_sets.hpp"
#include "../linalg/refined_solve.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseLU>

#include <cmath>
#include <sstream>

namespace contact::ddm {

namespace {

using SpMat = Eigen::SparseMatrix<double>;
using namespace monolithic;

// Solves `kkt` by sparse LU with two steps of iterative refinement (linalg/refined_solve.hpp); false when it is
// singular, and with `strict` also when it is so nearly singular that the refined solution does not solve it.
bool solve_refined(const SpMat& kkt, const Eigen::VectorXd& rhs, bool strict, Eigen::VectorXd& solution) {
  return linalg::refined_solve<Eigen::SparseLU<SpMat>>(kkt, rhs, 2, strict, solution);
}

// The saddle-point system of the sets, [K  -B^T P; R B  0] [x; y] = [b + B^T lambda0; -R g0]. Fills the iterate
// (lambda, h = g0 + B x, other = x); false when it is singular (the friction Newton then tries sets part of the way
// towards these). Strictly so with friction: there a nearly singular set's answer (multipliers of 1e12) sent the
// Newton cycling on every 4 x 4 wall with head joints at H/V = 0.5. Without friction the answer of a system that
// leaves a floating body free is taken as before (its rigid motion comes out about zero, one of many solutions),
// and solve() refuses a solution at which the contacts in contact do not hold every floating body, naming it.
bool solve_sets(const Stacked& s, const linalg::FrictionParametrization& p, linalg::FrictionIterate& iterate) {
  const Eigen::Index n = s.b.size(), na = static_cast<Eigen::Index>(p.rows.size());
  const SpMat BtP = SpMat(s.B.transpose()) * p.P;
  const Eigen::SparseMatrix<double, Eigen::RowMajor> Brows = s.B;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(s.K.nonZeros() + 2 * BtP.nonZeros()));
  for (int col = 0; col < s.K.outerSize(); ++col)
    for (SpMat::InnerIterator it(s.K, col); it; ++it) t.emplace_back(it.row(), it.col(), it.value());
  for (int col = 0; col < BtP.outerSize(); ++col)
    for (SpMat::InnerIterator it(BtP, col); it; ++it) t.emplace_back(it.row(), n + col, -it.value());
  Eigen::VectorXd rhs(n + na);
  rhs.head(n) = s.b + s.B.transpose() * p.lambda0;
  for (Eigen::Index i = 0; i < na; ++i) {
    const Eigen::Index row = p.rows[static_cast<size_t>(i)];
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(Brows, static_cast<int>(row)); it; ++it)
      t.emplace_back(n + i, it.col(), it.value());
    rhs[n + i] = -s.g0[row];
  }
  SpMat kkt(n + na, n + na);
  kkt.setFromTriplets(t.begin(), t.end());
  kkt.makeCompressed();
  Eigen::VectorXd solution;
  if (!solve_refined(kkt, rhs, !s.friction.empty(), solution)) return false;
  iterate.other = solution.head(n);
  iterate.lambda = p.P * solution.tail(na) + p.lambda0;
  iterate.h = s.g0 + s.B * iterate.other;
  return true;
}

bool any_floating(const ContactSystem& system) {
  bool floating = false;
  for (size_t a = 0; a < system.n_bodies(); ++a) floating = floating || system.body(a).floating();
  return floating;
}

// The paper's criterion: the largest relative change of a body's contact-zone normal displacements from `zone`
// to u's (0 unless `measure`); `zone` becomes u's.
double zone_change(const ContactSystem& system, const Displacements& u, std::vector<Eigen::VectorXd>& zone,
                   bool measure = true) {
  double paper = 0.0;
  for (size_t a = 0; a < system.n_bodies(); ++a) {
    const Eigen::VectorXd zn = system.zone_normals(a, u[a]);
    if (measure) paper = std::max(paper, relative_change(zn, zone[a]));
    zone[a] = zn;
  }
  return paper;
}

// The step the friction Newton did not settle (it stalled, or cycled through singular sets), solved again by the
// augmented Lagrangian (monolithic_friction.hpp) from the last converged answer, and its answer polished by a few
// Newton steps from the sets it predicts (exact on them, where the augmented Lagrangian's tolerance is its own). On
// success `result` becomes that answer (converged); else it keeps its stop. Returns what was done, in words for the
// outcome's message. `steps_before` counts the reported steps and is moved past those taken here.
template <class Report>
std::string by_augmented_lagrangian(const Stacked& s, const linalg::FrictionNewtonProblem& problem,
                                    const MonolithicMemory& memory, int& steps_before, const Report& report,
                                    linalg::FrictionNewtonResult& result) {
  const int newton_steps = static_cast<int>(result.report.iterations);
  const std::string why = result.report.stop == SolveStop::singular ? "reached only singular sets" : "did not settle";
  // The Newton on the sets an answer predicts: it confirms them where they are the solution's (exact on them).
  // Ten Newton steps from the sets an answer predicts; sets that failed once are not tried again (the answers of two
  // Coulomb iterations often predict the same).
  int attempts = 0;
  linalg::FrictionNewtonResult polished;
  linalg::FrictionSets tried;
  const auto confirm = [&](const AlmOutcome& answer) {
    linalg::FrictionSets sets =
        linalg::predict_friction_sets(answer.lambda, answer.h, problem.c, problem.rows, problem.mask);
    if (attempts > 0 && sets == tried) return false;
    ++attempts;
    tried = sets;
    linalg::FrictionNewtonSettings polish;
    polish.max_steps = 10;
    polish.tolerance = 1e-12;
    polished = linalg::friction_newton(problem, std::move(sets), polish);
    return polished.report.stop == SolveStop::converged;
  };
  const AlmOutcome alm = solve_by_augmented_lagrangian(
      s, problem.mask, problem.c, memory.x, memory.lambda, AlmSettings{},
      [&](int k, const Eigen::VectorXd& x, const Eigen::VectorXd& lambda, const Eigen::VectorXd& h, double comp) {
        return report(k, linalg::FrictionIterate{lambda, h, x}, comp, 0);
      },
      confirm, problem.cancelled);
  steps_before += alm.updates;
  std::ostringstream os;
  os << "the active-set Newton " << why << " in " << newton_steps << " steps; the augmented Lagrangian ";
  if (alm.cancelled) {
    result.report.stop = SolveStop::cancelled;
    return os.str() + "was cancelled";
  }
  if (!alm.converged) {
    os << "did not converge either (" << alm.failure << "; complementarity " << alm.complementarity << " after "
       << alm.updates << " updates)";
    return os.str();
  }
  os << "settled in " << alm.updates << " updates (" << alm.newton_steps << " Newton steps on the whole system)";
  if (alm.confirmed || confirm(alm)) {
    os << ", its sets confirmed by the Newton (" << attempts << (attempts == 1 ? " try" : " tries") << ")";
    result = std::move(polished);
    const double complementarity = linalg::friction_complementarity(result.iterate.lambda, result.iterate.h, problem.c,
                                                                    problem.rows, problem.mask);
    report(1, result.iterate, complementarity, 0);  // the confirmed answer, as one more step
    result.report.iterations = 1;
    return os.str();
  }
  result = linalg::FrictionNewtonResult{};
  result.report.stop = SolveStop::converged;
  result.iterate = linalg::FrictionIterate{alm.lambda, alm.h, alm.x};
  result.sets = linalg::predict_friction_sets(alm.lambda, alm.h, problem.c, problem.rows, problem.mask);
  return os.str();
}

// The method's outcome from the Newton's (or the augmented Lagrangian's) result: its stop in words, and the
// displacements and multipliers of its last iterate.
void record_outcome(const ContactSystem& system, const Stacked& s, const std::vector<char>& mask, bool floating,
                    const linalg::FrictionNewtonResult& result, const std::string& handed_over, MethodOutcome& out) {
  const Eigen::Index m = s.g0.size();
  switch (result.report.stop) {
    case SolveStop::converged: {
      out.converged = true;
      out.stop_reason = StopReason::converged;
      int na = 0;
      for (Eigen::Index j = 0; j < m; ++j)
        na += result.sets.active[static_cast<size_t>(j)] && !mask[static_cast<size_t>(j)];
      std::ostringstream os;
      os << "monolithic active set settled (" << na << " of " << s.row_offset.back() << " contact nodes in contact)";
      if (result.damped_steps > 0) os << "; " << result.damped_steps << " steps damped by the line search";
      if (!handed_over.empty()) os << "; " << handed_over;
      out.message = os.str();
      break;
    }
    case SolveStop::cancelled:
      out.stop_reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    case SolveStop::singular:
      out.stop_reason = StopReason::error;
      out.message = std::string("monolithic: the saddle-point system of the ") +
                    (s.friction.empty() ? "active set" : "stick and slip sets") + " is singular at step " +
                    std::to_string(result.report.iterations) +
                    (floating ? ": a floating body is held by none of the contact nodes in contact" : "") +
                    (handed_over.empty() ? "" : "; " + handed_over);
      return;
    case SolveStop::max_iterations:
      out.stop_reason = StopReason::max_iterations;
      out.message = "monolithic: the active set did not settle within max_iterations";
      if (!handed_over.empty()) out.message += "; " + handed_over;
      break;
  }
  const Eigen::VectorXd x = result.iterate.other.size() == s.b.size()
                                ? result.iterate.other
                                : Eigen::VectorXd(Eigen::VectorXd::Zero(s.b.size()));
  const Eigen::VectorXd lambda =
      result.iterate.lambda.size() == m ? result.iterate.lambda : Eigen::VectorXd(Eigen::VectorXd::Zero(m));
  out.u = to_bodies(system, s, x);
  out.z = split_rows(system, s, lambda);
  if (!s.friction.empty()) out.q = split_tangential(system, s, lambda);
}

void run_exact(const ContactSystem& system, RunFrame& frame, MonolithicMemory& memory) {
  MethodOutcome& out = frame.outcome();
  if (std::string sliding = friction_cannot_hold(system, frame.state().load);
      !sliding.empty()) {  // statics: no solver can hold it
    out.stop_reason = StopReason::error;
    out.refused = true;
    out.message = sliding;
    return;
  }
  const Stacked s = stack(system, frame.state(), false);
  const Eigen::Index m = s.g0.size();
  const std::vector<char> mask = tangential_unknowns(system, m, [&](size_t k) { return s.tangential_offset[k]; });
  const Eigen::VectorXd c = s.c.cwiseQuotient(s.D);  // prediction z - c g: g / D is the nodal gap
  // A floating body is held only by its contacts: start with every contact node active (the saddle-point system
  // of an empty active set would be singular), and let the active set shrink to the nodes that press. Nodes in
  // contact start sticking.
  const bool floating = any_floating(system);
  linalg::FrictionSets sets;
  sets.active.assign(static_cast<size_t>(m), 0);
  for (Eigen::Index r = 0; r < m; ++r) sets.active[static_cast<size_t>(r)] = floating && !mask[static_cast<size_t>(r)];
  linalg::stick_where_in_contact(sets, s.friction);
  std::vector<std::vector<char>> report_active;
  std::vector<Eigen::VectorXd> zone(system.n_bodies());
  bool first = true;
  const linalg::FrictionNewtonProblem problem{
      s.friction, mask, c,
      [&](const linalg::FrictionParametrization& p, linalg::FrictionIterate& it) { return solve_sets(s, p, it); },
      [&] { return frame.stop_requested(); }};
  linalg::FrictionNewtonSettings newton;
  newton.max_steps = std::max(1, frame.settings().max_iterations);
  newton.tolerance = 1e-12;
  if (!s.friction.empty()) {  // a stalling Newton hands the step to the augmented Lagrangian (below) at once
    newton.stall_steps = policy::kFrictionPolicy.direct.stall_steps;
    newton.stall_fall = policy::kFrictionPolicy.direct.stall_fall;
  }
  int steps_before = 0;  // of the runs before the current one (each numbers its steps from 1)
  const auto report = [&](int step, const linalg::FrictionIterate& it, double complementarity, int changes) {
    const Displacements u = to_bodies(system, s, it.other);
    const double paper = zone_change(system, u, zone, !first);
    first = false;
    const Pressures z = split_rows(system, s, it.lambda);
    IterationReport r = system.report(steps_before + step, u, z, report_active);
    if (!s.friction.empty()) system.report_friction(z, split_tangential(system, s, it.lambda), r);
    r.paper_criterion = paper;
    r.measure = Measure::complementarity;
    r.complementarity = complementarity;
    r.active_set_changes = changes;
    frame.report(std::move(r));
    return frame.stop_requested();
  };
  const auto on_step = [&](const linalg::FrictionIterate& it, const linalg::ActiveSetStep& step) {
    return report(step.step, it, step.complementarity, step.changes);
  };
  // From the last converged answer's sets where there is one (a load step, a cut's sub-step, a collapse trial: each
  // a small increment from it), else from the start above; where those leave a body held by nothing at once, from
  // the start above after all.
  const bool warm = memory.sets.active.size() == sets.active.size() && memory.sets.state.size() == sets.state.size();
  linalg::FrictionNewtonResult result = linalg::friction_newton(problem, warm ? memory.sets : sets, newton, on_step);
  if (warm && result.report.stop == SolveStop::singular && result.iterate.lambda.size() == 0) {
    steps_before += static_cast<int>(result.report.iterations);
    result = linalg::friction_newton(problem, std::move(sets), newton, on_step);
  }
  std::string handed_over;
  if (!s.friction.empty() &&
      (result.report.stop == SolveStop::max_iterations || result.report.stop == SolveStop::singular)) {
    steps_before += static_cast<int>(result.report.iterations);
    handed_over = by_augmented_lagrangian(s, problem, memory, steps_before, report, result);
  }
  if (result.report.stop == SolveStop::converged) {
    memory.sets = result.sets;
    memory.x = result.iterate.other;
    memory.lambda = result.iterate.lambda;
  }
  out.iterations = steps_before + static_cast<int>(result.report.iterations);
  record_outcome(system, s, mask, floating, result, handed_over, out);
}

// The penalty problem on the stacked system: the convex energy
// E(x) = 1/2 x^T K x - b^T x + sum_r 1 / (2 theta D_r) min(0, g_r(x))^2, its gradient and its Newton matrix.
struct PenaltyEnergy {
  const Stacked& s;
  Eigen::VectorXd w_over_theta;  // 1 / (theta D_r): the penalty stiffness of row r

  PenaltyEnergy(const ContactSystem& system, const Stacked& stacked) : s(stacked), w_over_theta(stacked.D.size()) {
    for (Eigen::Index r = 0; r < s.D.size(); ++r)
      w_over_theta[r] = 1.0 / (system.pairs()[static_cast<size_t>(s.row_pair[static_cast<size_t>(r)])].theta * s.D[r]);
  }

  double operator()(const Eigen::VectorXd& x) const {
    double e = 0.5 * x.dot(s.K * x) - s.b.dot(x);
    const Eigen::VectorXd g = s.g0 + s.B * x;
    for (Eigen::Index r = 0; r < g.size(); ++r)
      if (g[r] < 0) e += 0.5 * w_over_theta[r] * g[r] * g[r];
    return e;
  }

  Eigen::VectorXd gradient(const Eigen::VectorXd& x) const {
    const Eigen::VectorXd g = s.g0 + s.B * x;
    const Eigen::VectorXd f = w_over_theta.cwiseProduct(g.cwiseMin(0.0));
    return Eigen::VectorXd(s.K * x - s.b + s.B.transpose() * f);
  }

  // K + B^T W_A B on the active set of x (g < 0; with `touching`, g <= 0: a floating body's first step counts
  // the touching nodes too, or the matrix would be singular).
  SpMat newton_matrix(const Eigen::VectorXd& x, bool touching) const {
    const Eigen::VectorXd g = s.g0 + s.B * x;
    Eigen::VectorXd wa = Eigen::VectorXd::Zero(g.size());
    for (Eigen::Index r = 0; r < g.size(); ++r)
      if (g[r] < 0 || (touching && g[r] <= 0)) wa[r] = w_over_theta[r];
    return s.K + SpMat(s.B.transpose() * wa.asDiagonal() * s.B);
  }
};

// Backtracking (Armijo) line search on the convex energy from x along `step` (grad: the gradient at x); moves x
// and returns the step length taken.
double line_search(const PenaltyEnergy& energy, Eigen::VectorXd& x, const Eigen::VectorXd& step,
                   const Eigen::VectorXd& grad) {
  const double e0 = energy(x), slope = grad.dot(step);
  double alpha = 1.0;
  Eigen::VectorXd x_new = x + step;
  for (int ls = 0; ls < 30 && energy(x_new) > e0 + 1e-4 * alpha * slope + 1e-15 * std::abs(e0); ++ls) {
    alpha *= 0.5;
    x_new = x + alpha * step;
  }
  x = x_new;
  return alpha;
}

void run_penalty(const ContactSystem& system, RunFrame& frame) {
  MethodOutcome& out = frame.outcome();
  const Stacked s = stack(system, frame.state(), true);
  if (!s.friction.empty()) {  // (the job reader refuses it first, in the same words)
    out.stop_reason = StopReason::error;
    out.message = "monolithic: " + friction_conflict(frame.settings());
    return;
  }
  const PenaltyEnergy energy(system, s);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.b.size());
  const bool floating = any_floating(system);
  std::vector<std::vector<char>> active_report;
  std::vector<Eigen::VectorXd> zone(system.n_bodies());
  zone_change(system, to_bodies(system, s, x), zone, false);  // the start's zones
  const double b_norm = std::max(s.b.norm(), 1e-300);
  Eigen::CholmodDecomposition<SpMat, Eigen::Lower> factor;
  factor.cholmod().print = 0;  // a failed factorisation is reported by info(), not by CHOLMOD's text on stdout
  const int max_newton = std::max(frame.settings().max_iterations, 1);
  for (int k = 1; k <= max_newton; ++k) {
    if (frame.stop_requested()) {
      out.stop_reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    // Newton step on the current active set, then the line search.
    const Eigen::VectorXd grad = energy.gradient(x);
    factor.compute(energy.newton_matrix(x, k == 1 && floating));
    if (factor.info() != Eigen::Success) {
      out.stop_reason = StopReason::error;
      out.message = std::string("monolithic: the Newton matrix could not be factorised") +
                    (floating ? " (a floating body is not held by the contact nodes in contact)" : "");
      break;
    }
    const Eigen::VectorXd step = factor.solve(-grad);
    const double alpha = line_search(energy, x, step, grad);
    // Report: the paper's criterion and the relative energy gradient.
    const Displacements u = to_bodies(system, s, x);
    const double paper = zone_change(system, u, zone);
    const double residual = energy.gradient(x).norm() / b_norm;
    IterationReport r = system.report(k, u, frame.state(), active_report);
    r.paper_criterion = paper;
    r.measure = Measure::gradient;
    r.fixed_point_residual = residual;  // for Newton: the relative norm of the energy gradient
    const int changed = r.active_set_changes;
    frame.report(std::move(r));
    out.iterations = k;
    // Stop: the active set unchanged and the gradient or the step negligible.
    const double step_size = alpha * step.norm() / std::max(x.norm(), 1e-300);
    if (k > 1 && changed == 0 && (residual <= 1e-12 || step_size <= 1e-13)) {
      out.converged = true;
      out.stop_reason = StopReason::converged;
      std::ostringstream os;
      os << "Newton converged (active set unchanged, gradient " << residual << ")";
      out.message = os.str();
      break;
    }
    if (k == max_newton) {
      out.stop_reason = StopReason::max_iterations;
      out.message = "monolithic: Newton did not settle within max_iterations";
    }
  }
  out.u = to_bodies(system, s, x);
}

}  // namespace

void run_monolithic(const ContactSystem& system, RunFrame& frame, MonolithicMemory& memory) {
  if (frame.settings().enforcement == Enforcement::exact) return run_exact(system, frame, memory);
  run_penalty(system, frame);
}

}  // namespace contact::ddm
