// The iterative interface solver with friction (feti.hpp): SMALBE + MPRGP on the box of the normal and tangential
// multipliers. Tresca is one such solve: z >= 0, -g <= q <= g, a convex QP (linalg/friction_sets.hpp). Coulomb's
// bound mu z depends on the answer: an outer fixed point on the slip bounds b, each a Tresca problem with
// -b <= q <= b started from the last answer (and the last equality multipliers), b <- mu z, until the bounds
// stop moving and the friction complementarity of the Coulomb problem itself is below the tolerance
// (docs/algorithm.md, "Friction in the iterative solver", for why this outer iteration and what it costs).
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "../../linalg/anderson.hpp"
#include "../../linalg/friction_sets.hpp"
#include "../friction_policy.hpp"
#include "../friction_rows.hpp"
#include "feti.hpp"
#include "friction_direct.hpp"
#include "smalbe.hpp"

namespace contact::ddm {

namespace {

using linalg::FrictionRow;
using linalg::FrictionState;
using linalg::QpSolution;

constexpr double infinity = std::numeric_limits<double>::infinity();

// The friction problem as the direct solver sees it: its rows (without those no body can move tangentially), the
// tangential mask and the scaling c = 1 / diag(F) (from F's replicated diagonal; capped, below).
struct FrictionData {
  std::vector<FrictionRow> rows;
  std::vector<char> mask;
  Eigen::VectorXd c;
  bool coulomb = false;
};

FrictionData friction_data(const InterfaceProblem& problem, const Eigen::VectorXd& diagonal) {
  FrictionData d;
  const double dmax = diagonal.size() ? diagonal.cwiseAbs().maxCoeff() : 0.0;
  // The rows of every frictional solver (friction_rows.hpp): none where no body moves the node tangentially (a
  // symmetry line: q = 0 there, as in friction_direct). The mask covers every tangential row, those left out too:
  // friction_box fixes them at 0, and the complementarity and the sets' prediction skip them.
  d.rows = ddm::friction_rows(
      problem.system(), [&](size_t k) { return problem.offset(k); },
      [&](size_t k) { return problem.tangential_offset(k); },
      [&](Eigen::Index t) { return diagonal[t] > 1e-12 * dmax; });
  for (const auto& r : d.rows) d.coulomb = d.coulomb || r.coulomb;
  d.mask = ddm::tangential_unknowns(problem.system(), problem.size(),
                                    [&](size_t k) { return problem.tangential_offset(k); });
  // c = 1 / F_jj, but at most 1 / (1e-6 max F_jj): a row barely moved (a node next to a symmetry line, whose
  // tangential compliance is 1e-10 of the others on hertz_force.json) multiplies its slip, which the iterative
  // solve leaves at the products' rounding (1e-13 where the gaps are 1e-2), by 1e13 into a complementarity of 1
  // that no inner precision removes. The direct solver's c is the uncapped one; where no row is that stiff the two
  // are equal.
  d.c.resize(diagonal.size());
  for (Eigen::Index j = 0; j < d.c.size(); ++j) d.c[j] = 1.0 / std::max(diagonal[j], 1e-6 * dmax + 1e-300);
  return d;
}

// The box: z >= 0 on the normal rows, q = 0 on the tangential rows left out, -b <= q <= b on the others with b the
// Tresca bound or, for Coulomb rows, `slip_bound` (mu z of the last answer; +inf: tied).
Smalbe::Bounds friction_box(Eigen::Index size, const FrictionData& d, const Eigen::VectorXd& slip_bound) {
  Smalbe::Bounds box{Eigen::VectorXd::Zero(size), Eigen::VectorXd::Zero(size)};
  for (Eigen::Index j = 0; j < size; ++j)
    if (!d.mask[static_cast<size_t>(j)]) box.upper[j] = infinity;
  for (Eigen::Index j = 0; j < size; ++j)  // tangential rows not in d.rows stay fixed at 0
    if (d.mask[static_cast<size_t>(j)]) box.upper[j] = 0.0;
  for (size_t t = 0; t < d.rows.size(); ++t) {
    const auto& r = d.rows[t];
    const double b = r.coulomb ? slip_bound[static_cast<Eigen::Index>(t)] : r.bound;
    box.lower[r.tangential] = -b;
    box.upper[r.tangential] = b;
  }
  return box;
}

// Coulomb rows' bounds mu z from an answer (Tresca rows: unused, 0).
Eigen::VectorXd coulomb_bounds(const FrictionData& d, const Eigen::VectorXd& z) {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d.rows.size()));
  for (size_t t = 0; t < d.rows.size(); ++t)
    if (d.rows[t].coulomb) b[static_cast<Eigen::Index>(t)] = d.rows[t].mu * std::max(0.0, z[d.rows[t].normal]);
  return b;
}

std::string settled_message(const FrictionData& d, const QpSolution& out, int outer, const Smalbe& smalbe) {
  const linalg::FrictionSets sets = linalg::predict_friction_sets(out.z, out.h, d.c, d.rows, d.mask);
  int active = 0, stick = 0, slip = 0;
  for (char a : sets.active) active += a;
  for (auto st : sets.state) {
    stick += st == FrictionState::stick;
    slip += st == FrictionState::slip;
  }
  std::ostringstream os;
  os << "FETI (projected MPRGP on the box, SMALBE) with " << (d.coulomb ? "Coulomb" : "Tresca")
     << " friction converged: " << out.inner_iterations << " MPRGP iterations";
  if (d.coulomb) os << " in " << outer << " outer iterations on the slip bounds";
  const linalg::MprgpResult& steps = smalbe.mprgp_steps();
  os << " (" << smalbe.face_steps() << " of them in CG on settled faces; MPRGP's own steps " << steps.cg_steps
     << " CG, " << steps.expansion_steps << " expansion, " << steps.proportioning_steps << " proportioning; " << active
     << " nodes in contact: " << stick << " sticking, " << slip << " slipping; F products " << smalbe.seconds_F()
     << " s, coarse projections " << smalbe.seconds_coarse() << " s)";
  return os.str();
}

// The relative change of the Coulomb bounds (1 from or to an infinite bound: the tied first pass).
double bound_change(const Eigen::VectorXd& before, const Eigen::VectorXd& after) {
  if (!before.allFinite() || !after.allFinite()) return 1.0;
  return (after - before).norm() / std::max(after.norm(), 1e-300);
}

// The report of an outer iteration: nodes in contact, changes of the stick and slip sets, the complementarity.
linalg::ActiveSetStep outer_step(int outer, const FrictionData& d, const QpSolution& out,
                                 linalg::FrictionSets& previous) {
  linalg::FrictionSets sets = linalg::predict_friction_sets(out.z, out.h, d.c, d.rows, d.mask);
  linalg::ActiveSetStep info;
  info.step = outer;
  for (char a : sets.active) info.active += a;
  info.changes = outer == 1 ? info.active : sets.changes(previous);
  info.complementarity = linalg::friction_complementarity(out.z, out.h, d.c, d.rows, d.mask);
  previous = std::move(sets);
  return info;
}

// Coulomb: the outer fixed point b <- mu z on Tresca problems. The first bounds are mu z0 (the previous load
// step's or update's answer) or, without one (or if a floating body is not held on them), +inf: the tied problem,
// well posed whatever holds the floating bodies. Each Tresca solve starts from the last answer and equality
// multipliers and is solved to a hundredth of the bounds' last change (the first to 1e-3: its bounds are wrong by
// far more; a cap of 1e-6 cost 1.4x the MPRGP iterations on sheared walls, 1819 against 1302 at 16 x 16, H/V 0.3,
// and 2.4x at 12 x 12, H/V 0.5, 59506 against 24981, for the same answer; 1e-2 was too loose: the 8 x 8 wall's
// take-over without a preconditioner at H/V 0.5 then failed its whole increment), never below ten times the
// tolerance: a warm-started solve near the answer meets the projected gradient's rounding floor there (measured on
// roller_friction: ~1e-11 of the free response's penetration), and asking for less would stall SMALBE. Stops when the
// bounds moved by less than 1e3 x the tolerance and the Coulomb complementarity is below that too, or the bounds have
// settled (below): reduced quantities only, so every process takes the same decision.
void coulomb_outer(Smalbe& smalbe, const FrictionData& d, const Eigen::VectorXd* z0, Smalbe::Solve how,
                   double tolerance, InterfaceSolveContext& context, QpSolution& out) {
  const Eigen::Index n = smalbe.diagonal().size();
  const policy::CoulombOuter& tuning = policy::kFrictionPolicy.coulomb;
  const double outer_tolerance = tuning.stop_factor * tolerance;
  const Eigen::VectorXd tied = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(d.rows.size()), infinity);
  Eigen::VectorXd b = z0 && coulomb_bounds(d, *z0).maxCoeff() > 0 ? coulomb_bounds(d, *z0) : tied;
  how.report = false;
  linalg::FrictionSets previous;
  double change = 1.0;
  int settled = 0;
  how.tolerance = std::max(tuning.tolerance_floor * tolerance, tuning.first_tolerance);
  // The bounds Anderson-mixed (linalg/anderson.hpp): where the stick and slip sets no longer change, z(b) is affine
  // in b and the mixing converges like a Krylov method on it, where the plain update contracts by a constant factor
  // (about 0.5 per outer iteration on a sheared brick wall).
  linalg::NonnegativeAnderson mixing(tuning.anderson_depth);
  Eigen::VectorXd plain;  // the last plain update mu z, the fallback of mixed bounds
  bool mixed = false;
  for (int outer = 1; outer <= std::max(1, context.max_steps); ++outer) {
    // Never looser than the last: a solve that its start already satisfies leaves the bounds where they were, and
    // a tolerance from that zero change would loosen the next one again.
    how.tolerance = std::clamp(tuning.tolerance_per_change * change, tuning.tolerance_floor * tolerance, how.tolerance);
    smalbe.solve(friction_box(n, d, b), outer == 1 ? z0 : nullptr, how, out);
    if (out.report.cancelled()) return;
    if (!out.report.converged() && outer == 1 && b.allFinite()) {  // the warm start's bounds do not hold a body: tied
      b = tied;
      smalbe.solve(friction_box(n, d, b), z0, how, out);
      if (out.report.cancelled()) return;
    }
    if (!out.report.converged() && mixed) {  // the extrapolated bounds do not hold a body: the plain update instead
      mixing.reset();
      b = plain;
      smalbe.solve(friction_box(n, d, b), nullptr, how, out);
      if (out.report.cancelled()) return;
    }
    if (!out.report.converged()) return;  // unheld or out of iterations: out says which
    out.report.stop = SolveStop::max_iterations;
    const Eigen::VectorXd next = coulomb_bounds(d, out.z);
    change = bound_change(b, next);
    const linalg::ActiveSetStep info = outer_step(outer, d, out, previous);
    out.report.iterations = outer;
    if (context.on_step(out.z, out.h, info)) {
      out.report.stop = SolveStop::cancelled;
      out.report.message = "cancelled";
      return;
    }
    // Settled: the bounds stopped moving in two outer iterations at the finest inner tolerance. The complementarity
    // is then as small as the inner precision lets it be; above the tolerance only where a row's c = 1 / F_jj
    // magnifies the slip's rounding (see friction_data), which the message reports. Rounding of that kind stays below
    // 1e-6 (hertz_force with friction, c capped); a settled complementarity far above it is a slip against its friction
    // force that the bounds no longer correct (seen at 0.16 on a 16 x 16 wall with head joints at H/V = 0.5): not an
    // answer.
    settled = change <= outer_tolerance && how.tolerance <= tuning.tolerance_floor * tolerance ? settled + 1 : 0;
    const double settled_limit = tuning.settled_complementarity_limit;
    if (settled >= tuning.settled_iterations && info.complementarity > settled_limit) {
      std::ostringstream os;
      os.precision(3);
      os << "FETI with Coulomb friction: the slip bounds settled, but the Coulomb complementarity stays at "
         << info.complementarity << " (a node slips against its friction force) after " << outer << " outer iterations";
      out.report.message = os.str();
      return;
    }
    if (change <= outer_tolerance &&
        (info.complementarity <= outer_tolerance || settled >= tuning.settled_iterations)) {
      out.report.stop = SolveStop::converged;
      out.report.message = settled_message(d, out, outer, smalbe);
      if (info.complementarity > outer_tolerance) {
        std::ostringstream os;
        os.precision(3);
        os << "; the bounds settled with the complementarity at " << info.complementarity
           << " (the slips' rounding on rows of tiny tangential compliance)";
        out.report.message += os.str();
      }
      return;
    }
    plain = next;
    mixed = false;
    if (b.allFinite()) {  // not from the tied first pass (infinite bounds)
      b = mixing.next(next, next - b);
      mixed = mixing.mixed();
    } else {
      b = next;
    }
  }
  std::ostringstream os;
  os << "FETI with Coulomb friction: the slip bounds did not settle within " << context.max_steps
     << " outer iterations (last relative change " << change << ")";
  out.report.message = os.str();
}

}  // namespace

linalg::QpSolution FetiSolver::solve_friction(const InterfaceQp& qp, const Eigen::VectorXd* z0,
                                              InterfaceSolveContext& context) {
  QpSolution out;
  Smalbe smalbe(qp, settings_, context);
  if (!smalbe.prepare(out)) return out;
  const Eigen::Index n = qp.problem.size();
  const FrictionData d = friction_data(qp.problem, smalbe.diagonal());
  Smalbe::Solve how;
  how.tolerance = settings_.tolerance;
  how.measure = [&d](const Eigen::VectorXd& z, const Eigen::VectorXd& h) {
    return linalg::friction_complementarity(z, h, d.c, d.rows, d.mask);
  };
  const Eigen::VectorXd* start = z0 && z0->size() == n ? z0 : nullptr;
  if (!d.coulomb) {  // Tresca: one convex QP, reported per SMALBE outer iteration
    smalbe.solve(friction_box(n, d, Eigen::VectorXd()), start, how, out);
    if (out.report.converged())
      out.report.message = settled_message(d, out, static_cast<int>(out.report.iterations), smalbe);
    return out;
  }
  coulomb_outer(smalbe, d, start, how, settings_.tolerance, context, out);
  return out;
}

}  // namespace contact::ddm
