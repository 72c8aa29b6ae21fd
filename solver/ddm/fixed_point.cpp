#include "fixed_point.hpp"

#include "../linalg/anderson.hpp"

#include <cmath>
#include <random>
#include <sstream>

namespace contact::ddm {

namespace {

Eigen::VectorXd stacked_zone_normals(const ContactSystem& system, const Displacements& u) {
  std::vector<Eigen::VectorXd> parts(u.size());
  Eigen::Index n = 0;
  for (size_t a = 0; a < u.size(); ++a) {
    parts[a] = system.zone_normals(a, u[a]);
    n += parts[a].size();
  }
  Eigen::VectorXd out(n);
  Eigen::Index at = 0;
  for (const auto& p : parts) {
    out.segment(at, p.size()) = p;
    at += p.size();
  }
  return out;
}

// a + s * b, body by body.
Displacements axpy(const Displacements& a, double s, const Displacements& b) {
  Displacements out(a.size());
  for (size_t i = 0; i < a.size(); ++i) out[i] = a[i] + s * b[i];
  return out;
}

Displacements difference(const Displacements& a, const Displacements& b) { return axpy(a, -1.0, b); }

std::string format(const char* fmt, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, fmt, a, b, c);
  return buf;
}

}  // namespace

Pressures linear_pressures(const ContactSystem& system, const Displacements& du) {
  Pressures dz(system.pairs().size());
  for (size_t k = 0; k < dz.size(); ++k) {
    const auto& pair = system.pairs()[k];
    const Eigen::VectorXd dg = pair.Gm * du[static_cast<size_t>(pair.master_body)] - pair.Gs * du[static_cast<size_t>(pair.slave_body)];
    dz[k] = -dg.cwiseQuotient(pair.area) / pair.theta;
  }
  return dz;
}

Displacements NeumannMap::apply(const Displacements& u) { return system_.solve_bodies(system_.contact_loads(u), runner_); }

Displacements NeumannMap::linear_response(const Displacements& du) {
  const Displacements loads = system_.loads_from_pressures(linear_pressures(system_, du));
  Displacements out(loads.size());
  runner_.run_bodies(loads.size(), [&](size_t a) { out[a] = system_.body(a).solve_homogeneous(loads[a]); }, share_vectors(out));
  return out;
}

Displacements initial_iterate(const ContactSystem& system, const SolverSettings& settings, const RunContext& context,
                              int& solves) {
  if (context.warm_start) return *context.warm_start;
  if (settings.initial_guess == InitialGuess::elastic_layer) {
    solves += 2;
    return system.elastic_layer_guess(context.runner);
  }
  Displacements u(system.n_bodies());
  for (size_t a = 0; a < u.size(); ++a) u[a] = Eigen::VectorXd::Zero(system.body(a).n_dofs());
  return u;
}

double estimate_spectral_radius(const ContactSystem& system, BodyMap& map, int iterations, int& solves) {
  // Start from a random interface perturbation pushed once through the map (so it lies in its range).
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Displacements v(system.n_bodies());
  for (size_t a = 0; a < v.size(); ++a) {
    v[a] = Eigen::VectorXd(system.body(a).n_dofs());
    for (Eigen::Index i = 0; i < v[a].size(); ++i) v[a][i] = unit(rng);
  }
  v = map.linear_response(v);
  ++solves;
  double rho = 0.0;
  for (int it = 0; it < iterations; ++it) {
    const double norm_v = stacked_zone_normals(system, v).norm();
    if (!(norm_v > 0)) return 0.0;
    for (auto& x : v) x /= norm_v;
    Displacements w = map.linear_response(v);
    ++solves;
    const double previous = rho;
    rho = stacked_zone_normals(system, w).norm();
    v = std::move(w);
    if (it > 2 && std::abs(rho - previous) <= 1e-2 * rho) break;  // gamma needs no more than two digits
  }
  return rho;
}

MethodOutcome run_fixed_point(const ContactSystem& system, const SolverSettings& settings, RunContext& context,
                              BodyMap& map, Displacements u) {
  MethodOutcome out;
  const size_t n = system.n_bodies();
  int solves = 0;
  double gamma = settings.gamma;
  std::string pending_note;
  if (settings.gamma_auto) {
    // Eigenvalues of the relaxed map are 1 - gamma (1 - lambda) for F's eigenvalues lambda in [-rho, rho'];
    // gamma = 2 / (2 + rho) balances the stiffest and the slowest modes. 0.9 of it covers the estimate's error.
    const double rho = estimate_spectral_radius(system, map, 12, solves);
    gamma = std::min(1.0, 1.8 / (2.0 + rho));
    pending_note = format("gamma auto: spectral radius %.4g of the interface map, gamma = %.4g", rho, gamma);
  }
  const bool anderson_requested = settings.acceleration == Acceleration::anderson;
  bool anderson = anderson_requested;
  const size_t depth = static_cast<size_t>(std::max(1, settings.anderson_depth));

  std::vector<std::vector<char>> active;
  Eigen::VectorXd zone = stacked_zone_normals(system, u);
  std::vector<Eigen::VectorXd> zone_per_body(n);
  for (size_t a = 0; a < n; ++a) zone_per_body[a] = system.zone_normals(a, u[a]);

  // Anderson history: iterate and residual differences (full bodies) and interface-residual differences.
  linalg::AndersonHistory<std::pair<Displacements, Displacements>> history(depth);
  Displacements previous_u, previous_R;
  Eigen::VectorXd previous_r;
  int failed_restarts = 0, growth = 0, backoffs = 0;
  double smallest_residual = std::numeric_limits<double>::infinity(), last_residual = smallest_residual;
  double best_at_restart = smallest_residual;
  const int max_backoffs = 8;
  Displacements best_u = u;
  int best_iteration = 0;
  double marked_best = std::numeric_limits<double>::infinity();  // the residual at best_iteration
  const int stagnation_window = 100;

  for (int k = 1; k <= settings.max_iterations; ++k) {
    if (context.cancel.cancelled()) {
      out.reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    const Displacements u_tilde = map.apply(u);
    ++solves;
    const Eigen::VectorXd zone_tilde = stacked_zone_normals(system, u_tilde);
    const Eigen::VectorXd r = zone_tilde - zone;
    const double scale = std::max(zone.norm(), zone_tilde.norm());
    const double residual = scale > 0 ? r.norm() / scale : 0.0;
    const Displacements R = difference(u_tilde, u);
    std::string note = std::move(pending_note);
    pending_note.clear();

    // Progress is a 0.1 % improvement on the residual at the last marked best (not on the running minimum,
    // which a slow steady decrease would move every step without ever counting as progress).
    if (residual < 0.999 * marked_best) {
      best_iteration = k;
      marked_best = residual;
      best_u = u;
    }
    growth = residual > last_residual ? growth + 1 : 0;
    last_residual = residual;
    smallest_residual = std::min(smallest_residual, residual);

    Displacements next;
    // Anderson residuals are not monotone (its own restart handles overshoots), so under it only a large
    // growth counts.
    const bool growing = !std::isfinite(residual) ||
                         (anderson ? residual > 100.0 * smallest_residual
                                   : growth >= 3 && residual > 1.5 * smallest_residual);
    const bool stalled = k - best_iteration >= stagnation_window / 2;
    if (settings.gamma_auto && backoffs < max_backoffs && (growing || stalled)) {
      // Back off: a smaller gamma from the best iterate, history forgotten. A stall counts too: the penalty
      // switching points on and off can hold a too-large gamma in a cycle without any growth.
      gamma *= 0.5;
      ++backoffs;
      note = format(growing ? "gamma reduced to %.4g: the residual grew from %.3g to %.3g"
                            : "gamma reduced to %.4g: no progress below %.3g (now %.3g)",
                    gamma, smallest_residual, residual);
      best_iteration = k;
      next = best_u;
      history.clear();
      previous_u.clear();
      growth = 0;
    } else if (anderson) {
      if (!previous_u.empty()) history.push(r - previous_r, {difference(u, previous_u), difference(R, previous_R)});
      previous_u = u;
      previous_R = R;
      previous_r = r;
      next = axpy(u, gamma, R);
      // min || r - dr c || by QR; columns that make it ill-conditioned are dropped (oldest first).
      history.mix(r, [&](double c, const std::pair<Displacements, Displacements>& d) {
        for (size_t a = 0; a < n; ++a) next[a] -= c * (d.first[a] + gamma * d.second[a]);
      });
      // Safeguard: an accelerated residual ten times the best restarts the history from the best iterate;
      // four restarts in a row without a 10 % improvement of the best in between fall back to plain relaxation.
      if (residual > 10.0 * smallest_residual && !history.empty()) {
        failed_restarts = smallest_residual < 0.9 * best_at_restart ? 0 : failed_restarts + 1;
        best_at_restart = smallest_residual;
        note = "Anderson restarted (residual " + format("%.3g", residual) + " above ten times the best)";
        if (failed_restarts >= 4) {
          anderson = false;
          note = "Anderson acceleration abandoned after 4 restarts without progress: plain relaxation";
        }
        history.clear();
        previous_u.clear();
        next = axpy(best_u, gamma, difference(map.apply(best_u), best_u));
        ++solves;
      }
    } else {
      // Paper (17).
      next = axpy(u, gamma, R);
    }

    double paper = 0.0;
    for (size_t a = 0; a < n; ++a) {
      const Eigen::VectorXd z_new = system.zone_normals(a, next[a]);
      paper = std::max(paper, relative_change(z_new, zone_per_body[a]));
      zone_per_body[a] = z_new;
    }
    u = std::move(next);
    zone = stacked_zone_normals(system, u);

    IterationReport rep = system.report(k, u, active);
    rep.paper_criterion = paper;
    rep.fixed_point_residual = residual;
    rep.gamma = gamma;
    rep.note = note;
    rep.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(rep);
    out.history.push_back(std::move(rep));
    out.iterations = k;

    const double measure = settings.criterion == Criterion::paper ? paper : residual;
    if (measure <= settings.tolerance) {
      out.converged = true;
      out.reason = StopReason::converged;
      std::ostringstream os;
      os << (settings.criterion == Criterion::paper ? "paper's criterion " : "fixed-point residual ") << measure
         << " <= " << settings.tolerance;
      out.message = os.str();
      break;
    }
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
    if (!settings.gamma_auto &&
        (!std::isfinite(residual) || (k > 5 && residual > 1e3 * smallest_residual && residual > 1.0))) {
      std::ostringstream os;
      os << "the iteration diverges: the fixed-point residual grew from " << smallest_residual << " to " << residual
         << " at iteration " << k << "; reduce gamma (now " << gamma << ") or use gamma \"auto\"";
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
  if (anderson_requested && !anderson) out.message += " (Anderson acceleration was abandoned for plain relaxation)";
  out.u = std::move(u);
  out.gamma = gamma;
  out.solves_per_body = solves;
  return out;
}

}  // namespace contact::ddm
