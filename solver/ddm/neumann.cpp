// The paper's parallel Neumann domain decomposition, eqs. (16)-(17):
//   every body a solves  a_a(u~_a^{k+1}, v) = l_a(v) + (1/theta) int_S (d - u_1n^k - u_2n^k)^- v_an dS
//   independently (in parallel), then relaxes  u_a^{k+1} = gamma u~_a^{k+1} + (1 - gamma) u_a^k.
// Only the right-hand side changes between iterations, so each body's factorisation is reused throughout.
#include "method.hpp"

#include <cmath>
#include <sstream>

namespace contact::ddm {

MethodOutcome run_neumann(const ContactSystem& system, const SolverSettings& settings, RunContext& context) {
  MethodOutcome out;
  out.gamma = settings.gamma;
  const size_t n = system.n_bodies();
  std::vector<std::vector<char>> active;

  // Without contact pairs the bodies are independent: one solve each is the answer.
  if (system.pairs().empty()) {
    out.u = system.solve_bodies(Displacements(n), context.runner);
    out.iterations = 1;
    IterationReport r = system.report(1, out.u, active);
    r.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(r);
    out.history.push_back(std::move(r));
    out.converged = true;
    out.reason = StopReason::converged;
    out.message = "no contact pairs: each body solved once";
    return out;
  }

  Displacements u = settings.initial_guess == InitialGuess::elastic_layer ? system.elastic_layer_guess(context.runner)
                                                                           : Displacements(n);
  for (size_t a = 0; a < n; ++a)
    if (u[a].size() == 0) u[a] = Eigen::VectorXd::Zero(system.body(a).n_dofs());
  std::vector<Eigen::VectorXd> zone(n);
  for (size_t a = 0; a < n; ++a) zone[a] = system.zone_normals(a, u[a]);

  const double gamma = settings.gamma;
  double smallest_residual = std::numeric_limits<double>::infinity();
  int best_iteration = 0;  // where smallest_residual was reached (by a margin of 0.1 %)
  const int stagnation_window = 100;
  for (int k = 1; k <= settings.max_iterations; ++k) {
    if (context.cancel.cancelled()) {
      out.reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    // (16): every body with the contact tractions of the previous iterate, in parallel.
    const Displacements u_tilde = system.solve_bodies(system.contact_loads(u), context.runner);

    // The true fixed-point residual ||u~_n^{k+1} - u_n^k|| / ||u_n^k|| over all contact zones, and (17).
    double diff2 = 0.0, base2 = 0.0, paper = 0.0;
    for (size_t a = 0; a < n; ++a) {
      const Eigen::VectorXd zt = system.zone_normals(a, u_tilde[a]);
      diff2 += (zt - zone[a]).squaredNorm();
      base2 += std::max(zone[a].squaredNorm(), zt.squaredNorm());
      u[a] = gamma * u_tilde[a] + (1 - gamma) * u[a];
      const Eigen::VectorXd z_new = system.zone_normals(a, u[a]);
      // The paper's test (section 4): ||u_an^k - u_an^{k-1}|| / ||u_an^k|| for every body.
      paper = std::max(paper, relative_change(z_new, zone[a]));
      zone[a] = z_new;
    }
    const double residual = base2 > 0 ? std::sqrt(diff2 / base2) : 0.0;

    IterationReport r = system.report(k, u, active);
    r.paper_criterion = paper;
    r.fixed_point_residual = residual;
    r.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(r);
    out.history.push_back(std::move(r));
    out.iterations = k;

    const double measure = settings.criterion == Criterion::paper ? paper : residual;
    if (measure <= settings.tolerance) {
      out.converged = true;
      out.reason = StopReason::converged;
      std::ostringstream os;
      os << (settings.criterion == Criterion::paper ? "paper's criterion " : "fixed-point residual ") << measure
         << " <= " << settings.tolerance << " after " << k << " iterations";
      out.message = os.str();
      break;
    }
    if (residual < 0.999 * smallest_residual) best_iteration = k;
    smallest_residual = std::min(smallest_residual, residual);
    if (k - best_iteration >= stagnation_window) {
      // A relaxation above the stability bound does not always blow up: the penalty switching contact on and
      // off can lock it into a cycle (seen with gamma = 1 on seed_layers).
      std::ostringstream os;
      os << "the iteration stagnates: the fixed-point residual has not fallen below " << smallest_residual
         << " (reached at iteration " << best_iteration << ") in " << stagnation_window << " iterations";
      if (smallest_residual > 1e-6) os << "; gamma = " << gamma << " is probably above the stability bound: reduce it";
      out.reason = StopReason::stagnation;
      out.message = os.str();
      break;
    }
    if (!std::isfinite(residual) || (k > 5 && residual > 1e3 * smallest_residual && residual > 1.0)) {
      std::ostringstream os;
      os << "the iteration diverges: the fixed-point residual grew from " << smallest_residual << " to " << residual
         << " at iteration " << k << "; reduce gamma (now " << gamma << ")";
      out.reason = StopReason::error;
      out.message = os.str();
      break;
    }
    if (k == settings.max_iterations) {
      out.reason = StopReason::max_iterations;
      std::ostringstream os;
      os << "max_iterations = " << k << " reached; fixed-point residual " << residual << ", paper's criterion " << paper;
      out.message = os.str();
    }
  }
  out.u = std::move(u);
  return out;
}

}  // namespace contact::ddm
