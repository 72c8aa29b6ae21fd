// Interface Newton: the penalty contact problem reduced to the contact zones, solved exactly there.
//  1. Each body's contact-zone compliance S_a = E_a^T T K_red^{-1} T^T E_a (E_a selects the dofs the contact
//     operators touch) by blocked back-substitutions with the body's one factorisation; bodies in parallel.
//     Also each body's free response (its own loads, contact zone free).
//  2. With Q_a mapping zone displacements to normal jumps at all Gauss points (+G_s for a slave, -G_m for a
//     master), the gaps are affine in the pressures: g(p) = g_free + M W p, M = sum_a Q_a S_a Q_a^T.
//  3. Semismooth Newton (primal-dual active set) on p = max(0, lambda - g(p) / theta): on the active set A,
//     (W_A Theta_A + W_A M_AA W_A) p_A = -W_A g_eff_A (symmetric positive definite), then A is updated; the
//     map is piecewise linear, so the step on the right active set is exact.
//  4. One solve per body with the final pressures gives the fields.
// The bodies stay independent (only back-substitutions with their own factorisations); the interface system is
// dense but small (Gauss points on the contact edges).
#include "interface_newton.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <map>
#include <sstream>

namespace contact::ddm {

InterfaceNewton::InterfaceNewton(const ContactSystem& system, TaskRunner& runner) : system_(system) {
  const size_t n_bodies = system.n_bodies();
  const auto& pairs = system.pairs();
  auto& offset = offset_;
  auto& zones = zones_;

  // Global numbering of the Gauss points of all pairs.
  offset.assign(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) offset[k + 1] = offset[k] + pairs[k].n_points();
  const Eigen::Index nq = offset.back();
  weight_.resize(nq);
  theta_.resize(nq);
  for (size_t k = 0; k < pairs.size(); ++k) {
    weight_.segment(offset[k], pairs[k].n_points()) = pairs[k].weight;
    theta_.segment(offset[k], pairs[k].n_points()).setConstant(pairs[k].theta);
  }

  // 1. Zones and compliances.
  zones.resize(n_bodies);
  for (size_t a = 0; a < n_bodies; ++a) {
    std::vector<int> dofs;
    for (const auto& pair : pairs) {
      auto collect = [&](const Eigen::SparseMatrix<double, Eigen::RowMajor>& G) {
        for (int r = 0; r < G.outerSize(); ++r)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, r); it; ++it) dofs.push_back(static_cast<int>(it.col()));
      };
      if (static_cast<size_t>(pair.slave_body) == a) collect(pair.Gs);
      if (static_cast<size_t>(pair.master_body) == a) collect(pair.Gm);
    }
    std::sort(dofs.begin(), dofs.end());
    dofs.erase(std::unique(dofs.begin(), dofs.end()), dofs.end());
    zones[a].dofs = std::move(dofs);
  }
  runner.run(n_bodies, [&](size_t a) {
    BodyZone& z = zones[a];
    const auto& body = system.body(a);
    const auto& T = body.constraints().T();
    const Eigen::Index nz = static_cast<Eigen::Index>(z.dofs.size());
    // L = T^T E: row z_j of T, transposed.
    std::vector<Eigen::Triplet<double>> t;
    for (Eigen::Index j = 0; j < nz; ++j) {
      const Eigen::SparseMatrix<double> row = T.row(z.dofs[static_cast<size_t>(j)]);
      for (int c = 0; c < row.outerSize(); ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(row, c); it; ++it) t.emplace_back(it.col(), j, it.value());
    }
    Eigen::SparseMatrix<double> L(body.n_free(), nz);
    L.setFromTriplets(t.begin(), t.end());
    z.S.resize(nz, nz);
    const Eigen::Index block = 128;  // columns per blocked back-substitution (bounds the dense work array)
    for (Eigen::Index c0 = 0; c0 < nz; c0 += block) {
      const Eigen::Index cols = std::min(block, nz - c0);
      const Eigen::MatrixXd X = body.solve_reduced(Eigen::MatrixXd(L.middleCols(c0, cols)));
      z.S.middleCols(c0, cols) = L.transpose() * X;
    }
    const Eigen::VectorXd u_free = body.solve(Eigen::VectorXd());
    z.free_zone.resize(nz);
    for (Eigen::Index j = 0; j < nz; ++j) z.free_zone[j] = u_free[z.dofs[static_cast<size_t>(j)]];
    // Q: the pairs' rows restricted to the zone columns, signed.
    std::map<int, Eigen::Index> local;
    for (Eigen::Index j = 0; j < nz; ++j) local[z.dofs[static_cast<size_t>(j)]] = j;
    std::vector<Eigen::Triplet<double>> tq;
    for (size_t k = 0; k < pairs.size(); ++k) {
      auto add = [&](const Eigen::SparseMatrix<double, Eigen::RowMajor>& G, double sign) {
        for (int r = 0; r < G.outerSize(); ++r)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, r); it; ++it)
            tq.emplace_back(offset[k] + r, local.at(static_cast<int>(it.col())), sign * it.value());
      };
      if (static_cast<size_t>(pairs[k].slave_body) == a) add(pairs[k].Gs, 1.0);
      if (static_cast<size_t>(pairs[k].master_body) == a) add(pairs[k].Gm, -1.0);
    }
    z.Q.resize(nq, nz);
    z.Q.setFromTriplets(tq.begin(), tq.end());
  });
  for (const auto& z : zones) setup_solves_ = std::max(setup_solves_, static_cast<int>(z.dofs.size()) + 1);

  // 2. The interface system.
  M_ = Eigen::MatrixXd::Zero(nq, nq);
  free_jump_ = Eigen::VectorXd::Zero(nq);
  for (const auto& z : zones) {
    const Eigen::MatrixXd QS = z.Q * z.S;  // nq x nz
    M_.noalias() += QS * z.Q.transpose();
    free_jump_ += z.Q * z.free_zone;
  }
  M_ = 0.5 * (M_ + M_.transpose());
}

MethodOutcome InterfaceNewton::solve(const SolverSettings& settings, RunContext& context) const {
  MethodOutcome out;
  const ContactSystem& system = system_;
  const size_t n_bodies = system.n_bodies();
  const auto& pairs = system.pairs();
  const auto& offset = offset_;
  const auto& zones = zones_;
  const auto& weight = weight_;
  const auto& theta = theta_;
  const auto& M = M_;
  const Eigen::Index nq = offset.back();
  // Gaps with every body free, on the current (possibly multiplier-shifted) gaps.
  Eigen::VectorXd g_free = free_jump_;
  for (size_t k = 0; k < pairs.size(); ++k) g_free.segment(offset[k], pairs[k].n_points()) += pairs[k].effective_gap();

  // Zone displacements for the reports (zone dofs only; the rest stays zero until the final solve).
  auto partial_displacements = [&](const Eigen::VectorXd& p) {
    Displacements u(n_bodies);
    const Eigen::VectorXd wp = weight.cwiseProduct(p);
    for (size_t a = 0; a < n_bodies; ++a) {
      u[a] = Eigen::VectorXd::Zero(system.body(a).n_dofs());
      const Eigen::VectorXd uz = zones[a].free_zone + zones[a].S * (zones[a].Q.transpose() * wp);
      for (size_t j = 0; j < zones[a].dofs.size(); ++j) u[a][zones[a].dofs[j]] = uz[static_cast<Eigen::Index>(j)];
    }
    return u;
  };

  // 3. Primal-dual active set.
  std::vector<char> active(static_cast<size_t>(nq), 0);
  for (Eigen::Index q = 0; q < nq; ++q) active[static_cast<size_t>(q)] = weight[q] > 0 && g_free[q] < 0;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(nq);
  std::vector<std::vector<char>> report_active;
  std::vector<std::vector<char>> seen;
  const int max_steps = std::max(1, std::min(settings.max_iterations, 200));
  for (int k = 1; k <= max_steps; ++k) {
    if (context.cancel.cancelled()) {
      out.reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    std::vector<Eigen::Index> A;
    for (Eigen::Index q = 0; q < nq; ++q)
      if (active[static_cast<size_t>(q)]) A.push_back(q);
    const Eigen::Index na = static_cast<Eigen::Index>(A.size());
    Eigen::VectorXd p_new = Eigen::VectorXd::Zero(nq);
    if (na > 0) {
      Eigen::MatrixXd H(na, na);
      Eigen::VectorXd rhs(na);
      for (Eigen::Index i = 0; i < na; ++i) {
        for (Eigen::Index j = 0; j < na; ++j) H(i, j) = weight[A[i]] * M(A[i], A[j]) * weight[A[j]];
        H(i, i) += weight[A[i]] * theta[A[i]];
        rhs[i] = -weight[A[i]] * g_free[A[i]];
      }
      Eigen::LLT<Eigen::MatrixXd> llt(H);
      if (llt.info() != Eigen::Success) {
        out.reason = StopReason::error;
        out.message = "interface Newton: the active-set system is not positive definite";
        break;
      }
      const Eigen::VectorXd pa = llt.solve(rhs);
      for (Eigen::Index i = 0; i < na; ++i) p_new[A[i]] = pa[i];
    }
    const Eigen::VectorXd g = g_free + M * weight.cwiseProduct(p_new);
    std::vector<char> next(static_cast<size_t>(nq), 0);
    for (Eigen::Index q = 0; q < nq; ++q) {
      if (!(weight[q] > 0)) continue;
      next[static_cast<size_t>(q)] = active[static_cast<size_t>(q)] ? p_new[q] > 0 : g[q] < 0;
    }
    // Residual of the complementarity equation with p clipped to >= 0.
    Eigen::VectorXd clipped = p_new.cwiseMax(0.0);
    const Eigen::VectorXd g_clipped = g_free + M * weight.cwiseProduct(clipped);
    Eigen::VectorXd phi(nq);
    for (Eigen::Index q = 0; q < nq; ++q) phi[q] = weight[q] > 0 ? clipped[q] - std::max(0.0, -g_clipped[q] / theta[q]) : 0.0;
    const double scale = std::max(clipped.norm(), 1e-300);
    const double change = relative_change(clipped, p);
    p = clipped;

    IterationReport rep = system.report(k, partial_displacements(p), report_active);
    rep.paper_criterion = change;
    rep.fixed_point_residual = phi.norm() / scale;  // complementarity residual of the interface problem
    rep.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(rep);
    out.history.push_back(std::move(rep));
    out.iterations = k;
    if (next == active) {
      out.converged = true;
      out.reason = StopReason::converged;
      std::ostringstream os;
      os << "interface Newton: the active set settled after " << k << " steps (" << na << " of " << nq
         << " Gauss points in contact)";
      out.message = os.str();
      break;
    }
    if (std::find(seen.begin(), seen.end(), next) != seen.end()) {
      out.reason = StopReason::stagnation;
      out.message = "interface Newton: the active set cycles; use method neumann with gamma auto and Anderson";
      break;
    }
    seen.push_back(active);
    active = std::move(next);
    if (k == max_steps) {
      out.reason = StopReason::max_iterations;
      out.message = "interface Newton: the active set did not settle";
    }
  }

  // 4. The fields: one solve per body with the final pressures.
  std::vector<Eigen::VectorXd> pressures(pairs.size());
  for (size_t k = 0; k < pairs.size(); ++k) pressures[k] = p.segment(offset[k], pairs[k].n_points());
  out.u = system.solve_bodies(system.loads_from_pressures(pressures), context.runner);
  out.solves_per_body = 1;
  return out;
}

MethodOutcome run_interface_newton(const ContactSystem& system, const SolverSettings& settings, RunContext& context) {
  if (system.pairs().empty()) return run_neumann(system, settings, context);
  const InterfaceNewton solver(system, context.runner);
  MethodOutcome out = solver.solve(settings, context);
  out.solves_per_body += solver.setup_solves();
  return out;
}

}  // namespace contact::ddm
