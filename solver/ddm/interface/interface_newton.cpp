#include "interface_newton.hpp"

#include "../friction_policy.hpp"
#include "../friction_statics.hpp"
#include "feti.hpp"
#include "friction_direct.hpp"

#include <sstream>

namespace contact::ddm {

std::string InterfaceNewton::unheld_bodies(const std::vector<Eigen::Index>& rows) const {
  const Problem& problem = system_.problem();
  std::string text;
  for (const auto& f : problem_.floating()) {
    bool named = false;
    for (Eigen::Index row : rows) named = named || (row >= f.offset && row < f.offset + f.count);
    if (!named) continue;
    const auto& body = system_.body(f.body);
    std::string motions, pairs;
    for (const auto& m : body.rigid_mode_names()) motions += (motions.empty() ? "" : ", ") + m;
    for (const auto& c : problem.contacts)
      if (static_cast<size_t>(c.slave_body) == f.body || static_cast<size_t>(c.master_body) == f.body)
        pairs += (pairs.empty() ? "'" : ", '") + c.name + "'";
    text +=
        (text.empty() ? "" : "; ") +
        ("body '" + problem.bodies[f.body].name + "' floats (" + motions +
         " free) and no contact holds it: its contact" + (pairs.find(',') != std::string::npos ? "s " : " ") + pairs +
         " would have to pull (the loads move it away), or it is open at the solution;"
         " give it displacement conditions that hold it, or load it towards its contacts");
  }
  return text.empty() ? "the contact nodes in contact do not hold the floating bodies" : text;
}

std::vector<Eigen::VectorXd> InterfaceNewton::rigid_amplitudes(const Eigen::VectorXd& alpha) const {
  std::vector<Eigen::VectorXd> out(system_.n_bodies());
  if (alpha.size() != problem_.rigid_unknowns()) return out;
  for (const auto& f : problem_.floating()) out[f.body] = alpha.segment(f.offset, f.count);
  return out;
}

InterfaceQp InterfaceNewton::make_qp(const SolverSettings& settings, const RunState& state) const {
  const auto& pairs = system_.pairs();
  const Eigen::Index m = problem_.size();
  InterfaceQp qp{problem_, Eigen::VectorXd::Zero(m), problem_.free_gap(state), problem_.equilibrium(state.load), {},
                 {}};
  // H = F (+ theta D for the penalty), g = g_free (- theta D lambda under the augmented Lagrangian).
  if (settings.enforcement != Enforcement::exact)
    for (size_t k = 0; k < pairs.size(); ++k) {
      const auto& pair = pairs[k];
      const Eigen::VectorXd* lambda = state.multipliers_of(k, pair.n_rows());
      for (Eigen::Index r = 0; r < pair.n_rows(); ++r) {
        const Eigen::Index i = problem_.offset(k) + r;
        qp.penalty[i] = pair.theta * pair.area[r];
        if (lambda) qp.g[i] -= pair.theta * pair.area[r] * (*lambda)[r];
      }
    }
  // Each pair's rows are a line, ordered along the slave edge. A closed slave edge is the line cut at its start:
  // the nested guess's coarse spaces keep its first and last row as a line's ends. Every other row still lies
  // between two kept ones and the closing stretch between the last row and the first holds none, so it is a
  // coarse space like an open line's (a loop of odd length keeps two neighbours there); it only seeds the first
  // active set, and the solution is the same.
  qp.line.assign(static_cast<size_t>(m), -1);  // tangential rows lie on no line
  qp.position = Eigen::VectorXd::Zero(m);
  for (size_t k = 0; k < pairs.size(); ++k)
    for (Eigen::Index r = 0; r < pairs[k].n_rows(); ++r) {
      qp.line[static_cast<size_t>(problem_.offset(k) + r)] = static_cast<int>(k);
      qp.position[problem_.offset(k) + r] = pairs[k].node_arc[pairs[k].node_of_row[static_cast<size_t>(r)]];
    }
  return qp;
}

void InterfaceNewton::solve(RunFrame& frame) {
  const SolverSettings& settings = frame.settings();
  MethodOutcome& out = frame.outcome();
  const RunState& state = frame.state();
  // Loads not proportional to the last ones:
  if (system_.has_histories()) problem_.refresh_loads(frame.runner(), state.load);
  if (system_.has_friction())
    if (std::string overload = friction_cannot_hold(system_, state.load); !overload.empty()) {
      out.stop_reason = StopReason::error;
      out.refused = true;
      out.message = overload;
      return;
    }
  const InterfaceProblem& ip = problem_;
  const Eigen::Index m = ip.size();
  const InterfaceQp qp = make_qp(settings, state);

  std::vector<std::vector<char>> previous_active;
  const Eigen::VectorXd& penalty_diagonal = qp.penalty;     // theta area (0: exact)
  const Eigen::VectorXd shift = qp.g - ip.free_gap(state);  // -theta area lambda
  const std::string* solver_note = nullptr;  // what the solver says of its start (coarse solves), on the first report
  std::string solver_name = solver_->name();
  // The iterative solver's preconditioner, as `auto` resolved it (names.hpp's word).
  const std::string preconditioner_note =
      kind_ == InterfaceSolverKind::iterative
          ? std::string(", preconditioner ") + (settings_.preconditioner == InterfacePreconditioner::none ? "none"
                                                : settings_.preconditioner == InterfacePreconditioner::lumped
                                                    ? "lumped"
                                                    : "dirichlet")
          : std::string();
  const linalg::StepCallback on_step = [&](const Eigen::VectorXd& z, const Eigen::VectorXd& h,
                                           const linalg::ActiveSetStep& step) {
    // The reported gaps are the physical ones: h without the penalty's theta area z and the multipliers' shift.
    const Eigen::VectorXd gap = h - penalty_diagonal.cwiseProduct(z) - shift;
    IterationReport r =
        system_.report_gaps(step.step, ip.split(z), ip.split(gap.cwiseQuotient(ip.weights())), previous_active);
    if (system_.has_friction()) system_.report_friction(ip.split(z), ip.split_tangential(z), r);
    r.measure = Measure::complementarity;
    r.complementarity = step.complementarity;
    r.active_set_changes = step.changes;
    if (step.step == 1)
      r.note = std::string("interface solver ") + solver_name + preconditioner_note +
               (solver_note->empty() ? "" : "; ") + *solver_note;
    frame.report(std::move(r));
    return frame.stop_requested();
  };
  InterfaceSolveContext ctx{frame, on_step, std::max(1, settings.max_iterations), 0, {}, {}};
  if (last_z_.size() == m) ctx.alpha0 = last_alpha_;
  solver_note = &ctx.note;
  const Eigen::VectorXd* z0 = last_z_.size() == m && m > 0 && last_z_.cwiseAbs().maxCoeff() > 0 ? &last_z_ : nullptr;
  // With friction the direct solver's Newton gets a budget of its own before the iterative solver takes the step
  // over (below; the chain and the budget's rule: ddm/friction_policy.hpp).
  const bool may_take_over = system_.has_friction() && kind_ == InterfaceSolverKind::direct;
  if (may_take_over) {
    ctx.max_steps = std::min(ctx.max_steps, policy::kFrictionPolicy.direct.budget);
    ctx.stall_steps = policy::kFrictionPolicy.direct.stall_steps;
  }
  linalg::QpSolution result = solver_->solve(qp, z0, ctx);
  ctx.max_steps = std::max(1, settings.max_iterations);
  ctx.stall_steps = 0;
  bool took_over = false;
  if (may_take_over && !result.report.converged() && !result.report.cancelled()) {
    // The direct solver's semismooth Newton can cycle where friction holds (its stick and slip sets oscillating:
    // an 8 x 8 wall with mu = 0.05 under its precompression alone); the iterative solver's outer fixed point on
    // convex Tresca problems cannot cycle that way, and gives the same answer where both converge. It takes the
    // step over before the step is cut (on the blocks this problem holds, without a preconditioner: the direct
    // solver's problem has none).
    InterfaceSolverSettings iterative = settings_;
    iterative.preconditioner = InterfacePreconditioner::none;
    const std::string direct_said = result.report.message;  // why it stopped: stalled, singular sets, its budget
    solver_name = "iterative (the direct solver's friction Newton did not settle)";
    ctx.note.clear();
    linalg::QpSolution second = FetiSolver(iterative).solve(qp, z0, ctx);
    if (second.report.converged() || second.report.cancelled()) {
      result = std::move(second);
      took_over = true;
      if (result.report.converged())
        result.report.message =
            "the direct solver: " + direct_said + "; the iterative solver took the step over: " + result.report.message;
    } else {
      solver_name = solver_->name();
      result.report.message += "; the iterative solver did not settle it either: " + second.report.message;
    }
  }
  const int max_steps = ctx.max_steps;
  // The next solve starts from the last answer, not from a failed iterate (a cut load step's sub-step, a collapse
  // trial after one that did not hold: both restart from the last held state).
  if (result.report.converged()) {
    last_z_ = result.z;
    last_alpha_ = result.alpha;
  }
  out.iterations = static_cast<int>(result.report.iterations);
  out.interface_solver = took_over ? "iterative" : solver_->name();
  out.interface_iterations = result.inner_iterations;
  if (result.report.cancelled()) {
    out.stop_reason = StopReason::cancelled;
    out.message = "cancelled";
  } else if (result.report.converged()) {
    out.converged = true;
    out.stop_reason = StopReason::converged;
    out.message = "interface Newton: " + result.report.message;
  } else if (!result.unrestrained.empty()) {
    out.stop_reason = StopReason::error;
    out.message = "interface Newton: " + unheld_bodies(result.unrestrained);
    return;
  } else {
    out.stop_reason = result.report.iterations >= max_steps ? StopReason::max_iterations : StopReason::error;
    out.message = "interface Newton: " + result.report.message;
  }
  out.z = ip.split(result.z);
  if (system_.has_friction()) out.q = ip.split_tangential(result.z);
  out.u = ip.displacements(result.z, result.alpha, state.load);
  out.rigid_amplitudes = rigid_amplitudes(result.alpha);
  out.subdomain_solves = 1;
}

}  // namespace contact::ddm
