// Interface Newton: the penalty contact problem reduced to the contact zones and solved exactly there.
//  1. Each body's free response (its own loads, contact zone free) and the operators Q_a mapping its
//     contact-zone displacements to the normal jumps at all Gauss points (+G_s for a slave, -G_m for a master).
//  2. The gaps are affine in the pressures: g(p) = g_free + M W p, M = sum_a Q_a S_a Q_a^T, with S_a the body's
//     contact-zone compliance E^T T K_red^{-1} T^T E. Its columns cost one back-substitution each (blocked, with
//     the body's one factorisation, bodies in parallel), so only the columns that loads at *candidate* points
//     need are computed: the points the free response penetrates, plus two neighbours on each side.
//  3. Semismooth Newton (primal-dual active set) on p = max(0, lambda - g(p) / theta) over the candidates: on
//     the active set A, (W_A Theta_A + W_A M_AA W_A) p_A = -W_A g_eff_A (symmetric positive definite); the map
//     is piecewise linear, so the step on the right active set is exact.
//  4. The computed columns give the gaps at *every* point (M is symmetric), so the result is checked against
//     all of them: a point outside the candidates that would penetrate joins them (with its neighbours) and the
//     solve continues. The answer is therefore that of the full interface problem.
//  5. One solve per body with the final pressures gives the fields.
#include "interface_newton.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <map>
#include <sstream>

namespace contact::ddm {

namespace {

// Marks the points within `halo` positions (along the same pair) of a marked point.
std::vector<char> dilate(const std::vector<char>& marked, const std::vector<Eigen::Index>& offset, int halo) {
  std::vector<char> out = marked;
  for (size_t k = 0; k + 1 < offset.size(); ++k)
    for (Eigen::Index q = offset[k]; q < offset[k + 1]; ++q) {
      if (!marked[static_cast<size_t>(q)]) continue;
      for (Eigen::Index r = std::max(offset[k], q - halo); r <= std::min(offset[k + 1] - 1, q + halo); ++r)
        out[static_cast<size_t>(r)] = 1;
    }
  return out;
}

}  // namespace

InterfaceNewton::InterfaceNewton(const ContactSystem& system, TaskRunner& runner) : system_(system) {
  const size_t n_bodies = system.n_bodies();
  const auto& pairs = system.pairs();
  offset_.assign(pairs.size() + 1, 0);
  for (size_t k = 0; k < pairs.size(); ++k) offset_[k + 1] = offset_[k] + pairs[k].n_points();
  const Eigen::Index nq = offset_.back();
  weight_.resize(nq);
  theta_.resize(nq);
  for (size_t k = 0; k < pairs.size(); ++k) {
    weight_.segment(offset_[k], pairs[k].n_points()) = pairs[k].weight;
    theta_.segment(offset_[k], pairs[k].n_points()).setConstant(pairs[k].theta);
  }
  zones_.resize(n_bodies);
  runner.run(n_bodies, [&](size_t a) {
    BodyZone& z = zones_[a];
    for (const auto& pair : pairs) {
      auto collect = [&](const Eigen::SparseMatrix<double, Eigen::RowMajor>& G) {
        for (int r = 0; r < G.outerSize(); ++r)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, r); it; ++it)
            z.dofs.push_back(static_cast<int>(it.col()));
      };
      if (static_cast<size_t>(pair.slave_body) == a) collect(pair.Gs);
      if (static_cast<size_t>(pair.master_body) == a) collect(pair.Gm);
    }
    std::sort(z.dofs.begin(), z.dofs.end());
    z.dofs.erase(std::unique(z.dofs.begin(), z.dofs.end()), z.dofs.end());
    const Eigen::Index nz = static_cast<Eigen::Index>(z.dofs.size());
    z.S = Eigen::MatrixXd::Zero(nz, nz);
    z.have.assign(static_cast<size_t>(nz), 0);
    const Eigen::VectorXd u_free = system.body(a).solve(Eigen::VectorXd());
    z.solves = 1;
    z.free_zone.resize(nz);
    for (Eigen::Index j = 0; j < nz; ++j) z.free_zone[j] = u_free[z.dofs[static_cast<size_t>(j)]];
    std::map<int, Eigen::Index> local;
    for (Eigen::Index j = 0; j < nz; ++j) local[z.dofs[static_cast<size_t>(j)]] = j;
    std::vector<Eigen::Triplet<double>> tq;
    for (size_t k = 0; k < pairs.size(); ++k) {
      auto add = [&](const Eigen::SparseMatrix<double, Eigen::RowMajor>& G, double sign) {
        for (int r = 0; r < G.outerSize(); ++r)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, r); it; ++it)
            tq.emplace_back(offset_[k] + r, local.at(static_cast<int>(it.col())), sign * it.value());
      };
      if (static_cast<size_t>(pairs[k].slave_body) == a) add(pairs[k].Gs, 1.0);
      if (static_cast<size_t>(pairs[k].master_body) == a) add(pairs[k].Gm, -1.0);
    }
    z.Q.resize(nq, nz);
    z.Q.setFromTriplets(tq.begin(), tq.end());
  });
  free_jump_ = Eigen::VectorXd::Zero(nq);
  for (const auto& z : zones_) {
    free_jump_ += z.Q * z.free_zone;
    solves_ = std::max(solves_, z.solves);
  }
}

void InterfaceNewton::ensure_columns(const std::vector<char>& candidate, TaskRunner& runner) {
  runner.run(zones_.size(), [&](size_t a) {
    BodyZone& z = zones_[a];
    std::vector<Eigen::Index> missing;
    std::vector<char> needed(z.have.size(), 0);
    for (int r = 0; r < z.Q.outerSize(); ++r) {
      if (!candidate[static_cast<size_t>(r)]) continue;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(z.Q, r); it; ++it) needed[static_cast<size_t>(it.col())] = 1;
    }
    for (size_t j = 0; j < needed.size(); ++j)
      if (needed[j] && !z.have[j]) missing.push_back(static_cast<Eigen::Index>(j));
    if (missing.empty()) return;
    const auto& body = system_.body(a);
    const auto& T = body.constraints().T();
    // L = T^T E for the zone dofs (rows of T, transposed): the reduced load of a unit force at each zone dof.
    std::vector<Eigen::Triplet<double>> t;
    for (size_t j = 0; j < z.dofs.size(); ++j) {
      const Eigen::SparseMatrix<double> row = T.row(z.dofs[j]);
      for (int c = 0; c < row.outerSize(); ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(row, c); it; ++it)
          t.emplace_back(it.col(), static_cast<Eigen::Index>(j), it.value());
    }
    Eigen::SparseMatrix<double> L(body.n_free(), static_cast<Eigen::Index>(z.dofs.size()));
    L.setFromTriplets(t.begin(), t.end());
    const Eigen::SparseMatrix<double> Lt = L.transpose();
    const size_t block = 128;  // columns per blocked back-substitution (bounds the dense work array)
    for (size_t c0 = 0; c0 < missing.size(); c0 += block) {
      const size_t cols = std::min(block, missing.size() - c0);
      Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(body.n_free(), static_cast<Eigen::Index>(cols));
      for (size_t c = 0; c < cols; ++c) rhs.col(static_cast<Eigen::Index>(c)) = L.col(missing[c0 + c]);
      const Eigen::MatrixXd X = body.solve_reduced(rhs);
      const Eigen::MatrixXd SX = Lt * X;
      for (size_t c = 0; c < cols; ++c) {
        z.S.col(missing[c0 + c]) = SX.col(static_cast<Eigen::Index>(c));
        z.have[static_cast<size_t>(missing[c0 + c])] = 1;
      }
    }
    z.solves += static_cast<int>(missing.size());
  });
  for (const auto& z : zones_) solves_ = std::max(solves_, z.solves);
}

MethodOutcome InterfaceNewton::solve(const SolverSettings& settings, RunContext& context) {
  MethodOutcome out;
  const int solves_before = solves_;
  const ContactSystem& system = system_;
  const size_t n_bodies = system.n_bodies();
  const auto& pairs = system.pairs();
  const Eigen::Index nq = offset_.back();
  const Eigen::VectorXd& weight = weight_;
  // Gaps with every body free, on the current (possibly multiplier-shifted) gaps.
  Eigen::VectorXd g_free = free_jump_;
  for (size_t k = 0; k < pairs.size(); ++k) g_free.segment(offset_[k], pairs[k].n_points()) += pairs[k].effective_gap();

  // Zone displacements for the reports (zone dofs only; the rest stays zero until the final solve).
  auto partial_displacements = [&](const Eigen::VectorXd& p) {
    Displacements u(n_bodies);
    const Eigen::VectorXd wp = weight.cwiseProduct(p);
    for (size_t a = 0; a < n_bodies; ++a) {
      u[a] = Eigen::VectorXd::Zero(system.body(a).n_dofs());
      const Eigen::VectorXd uz = zones_[a].free_zone + zones_[a].S * (zones_[a].Q.transpose() * wp);
      for (size_t j = 0; j < zones_[a].dofs.size(); ++j) u[a][zones_[a].dofs[j]] = uz[static_cast<Eigen::Index>(j)];
    }
    return u;
  };

  std::vector<char> penetrating(static_cast<size_t>(nq), 0);
  for (Eigen::Index q = 0; q < nq; ++q) penetrating[static_cast<size_t>(q)] = weight[q] > 0 && g_free[q] < 0;
  std::vector<char> candidate = dilate(penetrating, offset_, 2);
  std::vector<char> active = penetrating;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(nq);
  std::vector<std::vector<char>> report_active, seen;
  const int max_steps = std::max(1, std::min(settings.max_iterations, 200));
  int k = 0;
  bool settled = false;
  while (!settled && k < max_steps) {
    // The columns of M for the candidates: M(:, C) = sum_a (Q_a S_a) Q_a(C, :)^T.
    ensure_columns(candidate, context.runner);
    std::vector<Eigen::Index> C;
    for (Eigen::Index q = 0; q < nq; ++q)
      if (candidate[static_cast<size_t>(q)]) C.push_back(q);
    const Eigen::Index nc = static_cast<Eigen::Index>(C.size());
    Eigen::MatrixXd MC = Eigen::MatrixXd::Zero(nq, nc);
    for (const auto& z : zones_) {
      const Eigen::MatrixXd QS = z.Q * z.S;  // nq x nz (only computed columns are non-zero)
      Eigen::SparseMatrix<double, Eigen::RowMajor> QC(nc, z.Q.cols());
      std::vector<Eigen::Triplet<double>> t;
      for (Eigen::Index i = 0; i < nc; ++i)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(z.Q, C[i]); it; ++it)
          t.emplace_back(i, it.col(), it.value());
      QC.setFromTriplets(t.begin(), t.end());
      MC.noalias() += QS * QC.transpose();
    }
    std::vector<Eigen::Index> position(static_cast<size_t>(nq), -1);
    for (Eigen::Index i = 0; i < nc; ++i) position[static_cast<size_t>(C[i])] = i;

    // Primal-dual active set on the candidates.
    for (; k < max_steps;) {
      ++k;
      if (context.cancel.cancelled()) {
        out.reason = StopReason::cancelled;
        out.message = "cancelled";
        settled = true;
        break;
      }
      std::vector<Eigen::Index> A;
      for (Eigen::Index i = 0; i < nc; ++i)
        if (active[static_cast<size_t>(C[i])]) A.push_back(i);
      const Eigen::Index na = static_cast<Eigen::Index>(A.size());
      Eigen::VectorXd p_new = Eigen::VectorXd::Zero(nq);
      if (na > 0) {
        Eigen::MatrixXd H(na, na);
        Eigen::VectorXd rhs(na);
        for (Eigen::Index i = 0; i < na; ++i) {
          const Eigen::Index qi = C[A[i]];
          for (Eigen::Index j = 0; j < na; ++j) H(i, j) = weight[qi] * MC(qi, A[j]) * weight[C[A[j]]];
          H(i, i) += weight[qi] * theta_[qi];
          rhs[i] = -weight[qi] * g_free[qi];
        }
        H = 0.5 * (H + H.transpose());
        Eigen::LLT<Eigen::MatrixXd> llt(H);
        if (llt.info() != Eigen::Success) {
          out.reason = StopReason::error;
          out.message = "interface Newton: the active-set system is not positive definite";
          settled = true;
          break;
        }
        const Eigen::VectorXd pa = llt.solve(rhs);
        for (Eigen::Index i = 0; i < na; ++i) p_new[C[A[i]]] = pa[i];
      }
      Eigen::VectorXd wp_c(nc);
      for (Eigen::Index i = 0; i < nc; ++i) wp_c[i] = weight[C[i]] * p_new[C[i]];
      const Eigen::VectorXd g = g_free + MC * wp_c;
      std::vector<char> next(static_cast<size_t>(nq), 0);
      for (Eigen::Index i = 0; i < nc; ++i) {
        const Eigen::Index q = C[i];
        if (weight[q] > 0) next[static_cast<size_t>(q)] = active[static_cast<size_t>(q)] ? p_new[q] > 0 : g[q] < 0;
      }
      const Eigen::VectorXd clipped = p_new.cwiseMax(0.0);
      for (Eigen::Index i = 0; i < nc; ++i) wp_c[i] = weight[C[i]] * clipped[C[i]];
      const Eigen::VectorXd g_clipped = g_free + MC * wp_c;
      Eigen::VectorXd phi = Eigen::VectorXd::Zero(nq);
      for (Eigen::Index q = 0; q < nq; ++q)
        if (weight[q] > 0) phi[q] = clipped[q] - std::max(0.0, -g_clipped[q] / theta_[q]);
      const double change = relative_change(clipped, p);
      p = clipped;

      IterationReport rep = system.report(k, partial_displacements(p), report_active);
      rep.paper_criterion = change;
      rep.fixed_point_residual = phi.norm() / std::max(p.norm(), 1e-300);  // complementarity residual
      rep.elapsed_seconds = context.elapsed();

      if (next == active) {
        // Settled on the candidates: every other point must stay open, else it joins the candidates.
        std::vector<char> violating(static_cast<size_t>(nq), 0);
        bool any = false;
        for (Eigen::Index q = 0; q < nq; ++q)
          if (!candidate[static_cast<size_t>(q)] && weight[q] > 0 && g[q] < 0) violating[static_cast<size_t>(q)] = any = true;
        if (any) {
          for (Eigen::Index q = 0; q < nq; ++q)
            if (violating[static_cast<size_t>(q)]) next[static_cast<size_t>(q)] = 1;
          const auto grown = dilate(violating, offset_, 2);
          for (size_t q = 0; q < grown.size(); ++q) candidate[q] = candidate[q] || grown[q];
          rep.note = "more contact points than the free response predicted: candidates extended";
          context.observer.on_iteration(rep);
          out.history.push_back(std::move(rep));
          active = std::move(next);
          break;  // recompute the columns for the new candidates
        }
        context.observer.on_iteration(rep);
        out.history.push_back(std::move(rep));
        out.converged = true;
        out.reason = StopReason::converged;
        std::ostringstream os;
        os << "interface Newton: the active set settled after " << k << " steps (" << na << " of " << nq
           << " Gauss points in contact; compliance columns for " << nc << " candidate points)";
        out.message = os.str();
        settled = true;
        break;
      }
      context.observer.on_iteration(rep);
      out.history.push_back(std::move(rep));
      if (std::find(seen.begin(), seen.end(), next) != seen.end()) {
        out.reason = StopReason::stagnation;
        out.message = "interface Newton: the active set cycles; use method neumann with gamma auto and Anderson";
        settled = true;
        break;
      }
      seen.push_back(active);
      active = std::move(next);
    }
  }
  out.iterations = k;
  if (!settled) {
    out.reason = StopReason::max_iterations;
    out.message = "interface Newton: the active set did not settle";
  }

  // The fields: one solve per body with the final pressures.
  std::vector<Eigen::VectorXd> pressures(pairs.size());
  for (size_t kk = 0; kk < pairs.size(); ++kk) pressures[kk] = p.segment(offset_[kk], pairs[kk].n_points());
  out.u = system.solve_bodies(system.loads_from_pressures(pressures), context.runner);
  out.solves_per_body = solves_ - solves_before + 1;
  return out;
}

MethodOutcome run_interface_newton(const ContactSystem& system, const SolverSettings& settings, RunContext& context) {
  if (system.pairs().empty()) return run_neumann(system, settings, context);
  InterfaceNewton solver(system, context.runner);
  const int setup = solver.solves();
  MethodOutcome out = solver.solve(settings, context);
  out.solves_per_body += setup;
  return out;
}

}  // namespace contact::ddm
