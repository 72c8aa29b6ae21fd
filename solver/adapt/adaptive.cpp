#include "adaptive.hpp"

#include "../ddm/fixed_point.hpp"
#include "indicator.hpp"

#include <cmath>
#include <sstream>

namespace contact::adapt {

namespace {

bool adapts(const AdaptivitySettings& s, size_t body) {
  return s.bodies.empty() || std::find(s.bodies.begin(), s.bodies.end(), static_cast<int>(body)) != s.bodies.end();
}

// Indicator of every adaptive body (empty vector for the others).
std::vector<IndicatorResult> estimate(const Problem& problem, const ddm::ContactSystem& system,
                                      const ddm::Displacements& u, const ddm::Displacements& contact_loads,
                                      ddm::TaskRunner& runner) {
  std::vector<IndicatorResult> out(problem.bodies.size());
  const ddm::BodyShare share{[&](size_t a, ddm::Packer& p) {
                               p.put(out[a].eta);
                               p.put(out[a].note);
                               p.put(out[a].seconds);
                             },
                             [&](size_t a, ddm::Unpacker& in) {
                               out[a].eta = in.get_vector();
                               out[a].note = in.get_string();
                               out[a].seconds = in.get_double();
                             }};
  runner.run_bodies(problem.bodies.size(), [&](size_t a) {
    if (!adapts(problem.adaptivity, a)) return;
    const Body& body = problem.bodies[a];
    const Normalization norm = problem.adaptivity.normalization;
    out[a] = problem.adaptivity.indicator == Indicator::fem_bem
                 ? fem_bem_indicator(body, problem.model, system.body(a), u[a], contact_loads[a], norm)
                 : zz_indicator(body, system.body(a), u[a], norm);
  }, share);
  return out;
}

struct RefineOutcome {
  std::vector<char> changed;
  std::vector<int> refined;  // cells split per body (closure included)
  std::vector<mesh::RefinementResult> refinements;
  std::string note;
  bool any = false;
};

// Notes are joined by "; " (none before the first or after the last).
void add_note(std::string& notes, const std::string& note) {
  if (note.empty()) return;
  if (!notes.empty()) notes += "; ";
  notes += note;
}

RefineOutcome mark_and_refine(Problem& problem, const std::vector<IndicatorResult>& eta) {
  const auto& s = problem.adaptivity;
  RefineOutcome out;
  const size_t n = problem.bodies.size();
  out.changed.assign(n, 0);
  out.refined.assign(n, 0);
  out.refinements.resize(n);
  for (size_t a = 0; a < n; ++a) {
    if (!adapts(s, a) || eta[a].eta.size() == 0) continue;
    auto& mesh = problem.bodies[a].mesh;
    const Marking m = mark(mesh, eta[a].eta, s.delta, s.max_level, s.max_dofs);
    if (m.dof_limit_hit) add_note(out.note, "body '" + problem.bodies[a].name + "': max_dofs reached, refinement cut back");
    if (m.level_limit_hit) add_note(out.note, "body '" + problem.bodies[a].name + "': cells at max_level not refined");
    add_note(out.note, eta[a].note);
    if (m.cells.empty()) continue;
    out.refinements[a] = mesh::refine(mesh, m.cells, s.max_level);
    out.refined[a] = out.refinements[a].refined_cells;
    out.changed[a] = out.refined[a] > 0;
    out.any = out.any || out.changed[a];
  }
  return out;
}

// u transferred to the refined meshes (new nodes interpolated from their parents).
void transfer(ddm::Displacements& u, const Problem& problem, const RefineOutcome& r) {
  for (size_t a = 0; a < u.size(); ++a) {
    if (!r.changed[a]) continue;
    const Eigen::MatrixXd old = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(u[a].data(), u[a].size() / 2, 2);
    const Eigen::MatrixXd moved = mesh::transfer(old, r.refinements[a], problem.bodies[a].mesh.num_nodes());
    Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> rowmajor = moved;
    u[a] = Eigen::Map<Eigen::VectorXd>(rowmajor.data(), rowmajor.size());
  }
}

Step make_step(const ddm::ContactSystem& system, const ddm::Displacements& u, const ddm::Pressures& z, int iteration,
               int index, const std::vector<IndicatorResult>& eta) {
  Step st = z.empty() ? system.fields(u, iteration) : system.fields(u, z, iteration);
  st.index = index;
  for (size_t a = 0; a < st.bodies.size() && a < eta.size(); ++a)
    if (eta[a].eta.size() == st.bodies[a].mesh.num_cells()) st.bodies[a].indicator_cell = eta[a].eta;
  return st;
}

ddm::MethodOutcome converge_then_refine(Problem& working, ddm::ContactSystem& system, ddm::RunContext& context,
                                        ddm::ContactMethod& method, std::vector<Step>& steps, int& updates) {
  const auto& s = working.adaptivity;
  ddm::MethodOutcome total;
  std::vector<int> refined_last;
  ddm::Displacements warm;
  for (int step = 0;; ++step) {
    ddm::OffsetObserver observer(context.observer, total.iterations, 0, refined_last);
    ddm::RunContext inner{observer, context.cancel, context.runner, context.start, warm.empty() ? nullptr : &warm};
    int step_updates = 0;
    ddm::MethodOutcome o = ddm::run_enforced(system, working.solver, inner, method, step_updates);
    updates += step_updates;
    for (auto& r : o.history) {
      r.iteration += total.iterations;
      if (!refined_last.empty())
        for (size_t a = 0; a < r.bodies.size(); ++a) r.bodies[a].elements_refined = refined_last[a];
      refined_last.clear();
      total.history.push_back(std::move(r));
    }
    total.iterations += o.iterations;
    total.add_work(o);
    total.gamma = o.gamma;
    total.u = o.u;
    total.z = o.z;
    total.reason = o.reason;
    total.converged = o.converged;
    total.message = o.message;
    if (o.u.empty()) return total;
    const ddm::Displacements loads = o.z.empty() ? system.contact_loads(o.u) : system.loads_from_pressures(o.z);
    const auto eta = estimate(working, system, o.u, loads, context.runner);
    for (const auto& e : eta) total.indicator_seconds += e.seconds;
    steps.push_back(make_step(system, o.u, o.z, total.iterations, step, eta));
    if (!o.converged) return total;
    if (step >= s.max_steps) {
      total.message = "adaptive: max_steps = " + std::to_string(s.max_steps) + " refinement steps done; " + o.message;
      return total;
    }
    RefineOutcome r = mark_and_refine(working, eta);
    if (!r.any) {
      std::ostringstream os;
      os << "adaptive: no cell marked after " << step << " refinement steps (" << (r.note.empty() ? "" : r.note + "; ") << "last solve: " << o.message << ")";
      total.message = os.str();
      return total;
    }
    warm = o.u;
    transfer(warm, working, r);
    system.rebuild(r.changed, context.runner);
    method.reset();
    refined_last = r.refined;
    if (!system.ok()) {
      total.reason = StopReason::error;
      total.converged = false;
      total.message = "adaptive: " + system.error();
      return total;
    }
  }
}

// The paper's interleaving: one Neumann update, then estimate and refine, every iteration.
ddm::MethodOutcome paper_interleaving(Problem& working, ddm::ContactSystem& system, ddm::RunContext& context,
                                      std::vector<Step>& steps) {
  const SolverSettings& settings = working.solver;
  ddm::MethodOutcome out;
  const size_t n = working.bodies.size();
  ddm::Displacements u = ddm::initial_iterate(system, settings, context, out.solves_per_body);
  double gamma = settings.gamma;
  if (settings.gamma_auto) {
    ddm::NeumannMap map(system, context.runner);
    int solves = 0;
    gamma = std::min(1.0, 1.8 / (2.0 + ddm::estimate_spectral_radius(system, map, 12, solves)));
    out.solves_per_body += solves;
  }
  out.gamma = gamma;
  std::vector<std::vector<char>> active;
  int step = 0;
  for (int k = 1; k <= settings.max_iterations; ++k) {
    if (context.cancel.cancelled()) {
      out.reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    // (16) on the current meshes, then (17).
    const ddm::Displacements loads = system.contact_loads(u);
    const ddm::Displacements u_tilde = system.solve_bodies(loads, context.runner);
    ++out.solves_per_body;
    double diff2 = 0, base2 = 0, paper = 0;
    ddm::Displacements u_new(n);
    for (size_t a = 0; a < n; ++a) {
      const Eigen::VectorXd z = system.zone_normals(a, u[a]), zt = system.zone_normals(a, u_tilde[a]);
      diff2 += (zt - z).squaredNorm();
      base2 += std::max(z.squaredNorm(), zt.squaredNorm());
      u_new[a] = gamma * u_tilde[a] + (1 - gamma) * u[a];
      paper = std::max(paper, ddm::relative_change(system.zone_normals(a, u_new[a]), z));
    }
    const double residual = base2 > 0 ? std::sqrt(diff2 / base2) : 0.0;
    const bool ddm_converged = (settings.criterion == Criterion::paper ? paper : residual) <= settings.tolerance;
    // Estimate on the body solutions of (16) with the contact tractions they were solved with.
    const auto eta = estimate(working, system, u_tilde, loads, context.runner);
    for (const auto& e : eta) out.indicator_seconds += e.seconds;
    IterationReport rep = system.report(k, u_new, active);
    rep.paper_criterion = paper;
    rep.fixed_point_residual = residual;
    rep.gamma = gamma;
    // Record the mesh state (before it is refined), then refine.
    Step st = make_step(system, u_new, {}, k, step, eta);
    RefineOutcome r = mark_and_refine(working, eta);
    for (size_t a = 0; a < n; ++a) rep.bodies[a].elements_refined = r.refined[a];
    rep.note = r.note;
    rep.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(rep);
    out.history.push_back(std::move(rep));
    out.iterations = k;
    if (!r.any) {
      if (ddm_converged) {
        steps.push_back(std::move(st));
        out.converged = true;
        out.reason = StopReason::converged;
        std::ostringstream os;
        os << "adaptive (paper): the DDM criterion holds and no cell is marked (" << step << " refinements)";
        out.message = os.str();
        u = std::move(u_new);
        break;
      }
      u = std::move(u_new);
    } else {
      steps.push_back(std::move(st));
      ++step;
      transfer(u_new, working, r);
      system.rebuild(r.changed, context.runner);
      if (!system.ok()) {
        out.reason = StopReason::error;
        out.message = "adaptive: " + system.error();
        u = std::move(u_new);
        break;
      }
      u = std::move(u_new);
    }
    if (!std::isfinite(residual)) {
      out.reason = StopReason::error;
      out.message = "the iteration diverges; reduce gamma";
      break;
    }
    if (k == settings.max_iterations) {
      out.reason = StopReason::max_iterations;
      out.message = "adaptive (paper): max_iterations reached";
      steps.push_back(make_step(system, u, {}, k, step, {}));
    }
  }
  out.u = std::move(u);
  return out;
}

}  // namespace

ddm::MethodOutcome run_adaptive(Problem& working, ddm::ContactSystem& system, ddm::RunContext& context,
                                ddm::ContactMethod& method, std::vector<Step>& steps, int& updates) {
  updates = 0;
  if (working.adaptivity.strategy == AdaptStrategy::paper) return paper_interleaving(working, system, context, steps);
  return converge_then_refine(working, system, context, method, steps, updates);
}

}  // namespace contact::adapt
