#include "friction_direct.hpp"

#include "../../linalg/friction_nested.hpp"
#include "../../linalg/friction_newton.hpp"
#include "../friction_policy.hpp"
#include "../friction_rows.hpp"

#include <Eigen/SVD>

#include <cmath>
#include <limits>
#include <sstream>

namespace contact::ddm {

namespace {

using linalg::FrictionRow;
using linalg::FrictionSets;
using linalg::FrictionState;

// The first sets: the frictionless normal problem's (with the equilibrium normal pressures can meet; from nested
// coarse solves, which keeps the number of steps independent of the mesh, also at a new load step, where the
// previous step's sets would move the zone's edge by a few nodes per step); where that fails, the warm start's
// prediction, or every normal row active (floating bodies) or those that overlap. Every node in contact sticks:
// the tied problem under the loads is well posed (friction holds the floating bodies). The solver then predicts
// better sets from coarse friction solves (first_sets_from_coarse) and comes back here if those fail.
FrictionSets first_sets(const SparseMatrix& F, const InterfaceQp& qp, const Eigen::VectorXd* z0,
                        const Eigen::VectorXd& alpha0, const Eigen::VectorXd& c, const std::vector<FrictionRow>& rows,
                        const std::vector<char>& mask, std::string& note) {
  const Eigen::Index n = qp.g.size(), m = qp.problem.normal_size();
  Eigen::VectorXd lambda = Eigen::VectorXd::Zero(n);
  const SparseMatrix Fnn = F.topLeftCorner(m, m);
  const Eigen::VectorXd gn = qp.g.head(m);
  const linalg::Equalities held = linalg::normal_equalities(qp.equilibrium, m);
  const std::vector<int> line(qp.line.begin(), qp.line.begin() + m);
  const Eigen::VectorXd guess = linalg::nested_initial_guess(Fnn, gn, line, qp.position.head(m), held);
  const linalg::StepCallback quiet = [](const Eigen::VectorXd&, const Eigen::VectorXd&, const linalg::ActiveSetStep&) {
    return false;
  };
  const linalg::QpSolution normal = linalg::solve_active_set(Fnn, gn, 100, quiet, &guess, held);
  if (normal.report.converged()) {
    lambda.head(m) = normal.z;
    note =
        "first sets from the frictionless solution (" + std::to_string(normal.report.iterations) + " active-set steps)";
  }
  const bool solved = lambda.cwiseAbs().maxCoeff() > 0;
  if (!solved && z0 && z0->size() == n && z0->cwiseAbs().maxCoeff() > 0) {
    // The normal sets predicted from the previous answer (with its rigid amplitudes); every node in contact
    // sticking.
    Eigen::VectorXd h = qp.g + F * *z0;
    if (alpha0.size() == qp.equilibrium.G.rows() && alpha0.size() > 0) h += qp.equilibrium.G.transpose() * alpha0;
    FrictionSets s = linalg::predict_friction_sets(*z0, h, c, rows, mask);
    linalg::stick_where_in_contact(s, rows);
    return s;
  }
  // Its pressing nodes are the first normal set (its own gaps, with its rigid amplitudes, confirm them).
  FrictionSets s;
  s.active.assign(static_cast<size_t>(n), 0);
  for (Eigen::Index j = 0; j < m; ++j)
    s.active[static_cast<size_t>(j)] = solved ? lambda[j] > 0 : !qp.equilibrium.empty() || qp.g[j] < 0;
  linalg::stick_where_in_contact(s, rows);
  return s;
}

}  // namespace

namespace {

// The first sets from coarse friction solves (linalg/friction_nested.hpp) over the sticking start: false (and the
// sets unchanged) when there is no coarser level or a coarse problem could not be solved.
bool first_sets_from_coarse(const SparseMatrix& F, const InterfaceQp& qp, const std::vector<FrictionRow>& rows,
                            const std::vector<char>& mask, FrictionSets& sets, std::string& note) {
  const Eigen::Index m = qp.problem.normal_size();
  if (static_cast<Eigen::Index>(qp.line.size()) < m || qp.position.size() < m) return false;
  const std::vector<int> line(qp.line.begin(), qp.line.begin() + m);  // the normal rows' (tangential: on none)
  const Eigen::VectorXd position = qp.position.head(m);
  const linalg::FrictionLevel level{F, qp.g, qp.equilibrium, rows, mask, m, line, position};
  std::vector<int> coarse_steps;
  FrictionSets nested;
  if (!linalg::nested_friction_sets(level, nested, &coarse_steps)) return false;
  sets = std::move(nested);
  std::string steps;
  for (int k : coarse_steps) steps += (steps.empty() ? "" : ", ") + std::to_string(k);
  note += std::string(note.empty() ? "" : "; ") + "stick and slip sets from coarse friction solves (" + steps +
          " steps, finest first)";
  return true;
}

// The floating bodies whose rigid motions the rows of `sets` leave free, as "body 'b1_1' (1 of its 3 rigid
// motions)": the rows of G P of each body (G its equilibrium rows, P the sets' parametrisation of the free
// multipliers: open rows fixed at 0, slip rows tied to their normal) of rank below their count. Each row is
// scaled to unit length first (forces and moments have different units). Empty if every body is held row by row
// (a group of bodies held by nothing together is not named).
std::string bodies_held_by_nothing(const InterfaceQp& qp, const FrictionSets& sets,
                                   const std::vector<FrictionRow>& rows, const std::vector<char>& mask) {
  if (qp.equilibrium.G.rows() == 0 || sets.active.size() != static_cast<size_t>(qp.g.size())) return "";
  const linalg::FrictionParametrization p = linalg::parametrize(sets, rows, mask);
  const SparseMatrix GP = qp.equilibrium.G * p.P;
  const auto& bodies = qp.problem.system().problem().bodies;
  std::ostringstream os;
  int named = 0, more = 0;
  for (const auto& f : qp.problem.floating()) {
    Eigen::MatrixXd block = SparseMatrix(GP.middleRows(f.offset, f.count)).toDense();
    int free = 0;
    for (Eigen::Index i = 0; i < block.rows(); ++i) {
      const double norm = block.row(i).norm();
      if (norm > 0) block.row(i) /= norm;
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(block * block.transpose());
    const Eigen::VectorXd s = svd.singularValues();
    for (Eigen::Index i = 0; i < s.size(); ++i) free += s[i] <= 1e-12 * std::max(1.0, s.size() ? s[0] : 1.0);
    if (free == 0) continue;
    if (named == 5) {
      ++more;
      continue;
    }
    os << (named ? ", " : "") << "body '" << bodies[f.body].name << "' (" << free << " of its " << f.count
       << " rigid motions)";
    ++named;
  }
  if (more > 0) os << " and " << more << " more";
  return os.str();
}

// The stop of the Newton as the interface solver's answer.
void describe_stop(const linalg::FrictionNewtonResult& r, const InterfaceQp& qp, int max_steps, double complementarity,
                   const std::string& unheld, linalg::QpSolution& result) {
  result.report.iterations = r.report.iterations;
  result.report.stop = r.report.stop;
  switch (r.report.stop) {
    case SolveStop::converged: {
      int stick = 0, slip = 0, active = 0;
      for (auto st : r.sets.state) {
        stick += st == FrictionState::stick;
        slip += st == FrictionState::slip;
      }
      for (Eigen::Index j = 0; j < qp.problem.normal_size(); ++j) active += r.sets.active[static_cast<size_t>(j)];
      std::ostringstream os;
      os << "stick and slip sets settled in " << r.report.iterations << " steps (" << active
         << " nodes in contact: " << stick << " sticking, " << slip << " slipping)";
      if (r.damped_steps > 0) os << "; " << r.damped_steps << " steps damped by the line search";
      result.report.stop = SolveStop::converged;
      result.report.message = os.str();
      return;
    }
    case SolveStop::cancelled:
      result.report.stop = SolveStop::cancelled;
      return;
    case SolveStop::singular: {
      // Statics has refused the loads that friction cannot carry along flat joints before the solve
      // (friction_statics.hpp); whether the rest is a collapse or the solver, solve() judges by the rigid-block
      // statics of the whole (limit/verdict.hpp) once the run has stopped.
      std::ostringstream os;
      os.precision(3);
      os << "the friction Newton did not converge: at step " << r.report.iterations
         << " the stick and slip sets it predicted, and every set between them and the last solved one, leave a "
            "floating body (or a group of them) held by nothing (a singular system"
         << (unheld.empty() ? std::string() : "; the predicted sets hold no contact node that fixes " + unheld)
         << "); the complementarity residual of the last iterate is " << complementarity;
      result.report.message = os.str();
      return;
    }
    case SolveStop::max_iterations: {
      std::ostringstream os;
      os.precision(3);
      if (r.stalled)
        os << "the stick and slip sets did not settle: the friction Newton stalled (its merit fell by less than "
           << 1 / policy::kFrictionPolicy.direct.stall_fall << "x over its last "
           << policy::kFrictionPolicy.direct.stall_steps << " steps; " << r.accepted_steps << " steps, "
           << r.report.iterations << " linear solves; complementarity residual " << complementarity
           << " at the last iterate)";
      else
        os << "the stick and slip sets did not settle within " << max_steps << " steps (complementarity residual "
           << complementarity << " at the last iterate)";
      result.report.message = os.str();
      return;
    }
  }
}

}  // namespace

linalg::QpSolution FrictionDirectSolver::solve(const InterfaceQp& qp, const Eigen::VectorXd* z0,
                                               InterfaceSolveContext& context) {
  const Eigen::Index n = qp.problem.size();
  const SparseMatrix& F = compliance_.of(qp.problem);
  const Eigen::VectorXd diagonal = F.diagonal();
  const double dmax = diagonal.cwiseAbs().maxCoeff();
  // A node whose tangential motion both sides prescribe (on a symmetry line) cannot slip: its row of F is zero and
  // its tangential traction goes into the supports; it is left out (q = 0 there).
  const std::vector<FrictionRow> rows = ddm::friction_rows(
      qp.problem.system(), [&](size_t k) { return qp.problem.offset(k); },
      [&](size_t k) { return qp.problem.tangential_offset(k); },
      [&](Eigen::Index t) { return diagonal[t] > 1e-12 * dmax; });
  const std::vector<char> mask =
      ddm::tangential_unknowns(qp.problem.system(), n, [&](size_t k) { return qp.problem.tangential_offset(k); });
  const Eigen::VectorXd c = linalg::friction_scaling(F);
  const Eigen::VectorXd alpha0 = context.alpha0.size() == qp.equilibrium.G.rows() ? context.alpha0 : Eigen::VectorXd();
  const FrictionSets sticking = first_sets(F, qp, z0, alpha0, c, rows, mask, context.note);
  FrictionSets sets = sticking;
  const bool from_coarse = first_sets_from_coarse(F, qp, rows, mask, sets, context.note);

  const linalg::FrictionNewtonProblem problem{
      rows, mask, c,
      [&](const linalg::FrictionParametrization& p, linalg::FrictionIterate& x) {
        return linalg::solve_on_friction_sets(F, qp.g, qp.equilibrium, p, x);
      },
      [&] { return context.frame.stop_requested(); }};
  linalg::FrictionNewtonSettings settings;
  settings.max_steps = context.max_steps;
  settings.stall_steps = context.stall_steps;
  settings.stall_fall = policy::kFrictionPolicy.direct.stall_fall;
  const linalg::FrictionStepCallback on_step = [&](const linalg::FrictionIterate& x,
                                                   const linalg::ActiveSetStep& info) {
    return context.on_step(x.lambda, x.h, info);
  };
  linalg::FrictionNewtonResult r = linalg::friction_newton(problem, sets, settings, on_step);
  if (r.report.stop == SolveStop::singular && r.iterate.lambda.size() == 0 && from_coarse)
    r = linalg::friction_newton(problem, sticking, settings, on_step);  // the coarse guess leaves a body unheld

  linalg::QpSolution result;
  result.z = r.iterate.lambda.size() == n ? r.iterate.lambda : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
  result.h = r.iterate.h;
  result.alpha = r.iterate.other;
  const double residual = r.iterate.lambda.size() == n
                              ? linalg::friction_complementarity(r.iterate.lambda, r.iterate.h, c, rows, mask)
                              : 1.0;
  const std::string unheld =
      r.report.stop == SolveStop::singular ? bodies_held_by_nothing(qp, r.unsolvable, rows, mask) : std::string();
  describe_stop(r, qp, context.max_steps, residual, unheld, result);
  return result;
}

}  // namespace contact::ddm
