// Reference solver: the same discrete penalty problem as the DDM, all bodies in one system.
// Unknowns x = (x_1, ..., x_N), the free dofs of every body (u_a = T_a x_a + g_a). The energy
//   Pi(x) = sum_a (1/2 x_a^T K_a x_a - b_a^T x_a) + sum_q w_q / (2 theta) min(0, g_q(x))^2,
//   g(x) = d~ + B x  (B, d~ from each pair's G_s, G_m and the prescribed values),
// is convex and piecewise quadratic; semismooth Newton (active-set) steps with a backtracking line search
// converge to its minimiser, and the final step on the right active set is exact up to round-off.
#include "method.hpp"

#include <Eigen/CholmodSupport>

#include <cmath>
#include <sstream>

namespace contact::ddm {

namespace {

struct GlobalPair {
  Eigen::SparseMatrix<double> B;  // Q x n_total
  Eigen::VectorXd d;              // d~
  Eigen::VectorXd w_over_theta;   // w_q / theta
};

}  // namespace

MethodOutcome run_monolithic(const ContactSystem& system, const SolverSettings& settings, RunContext& context) {
  MethodOutcome out;
  const size_t n_bodies = system.n_bodies();
  std::vector<Eigen::Index> offset(n_bodies + 1, 0);
  for (size_t a = 0; a < n_bodies; ++a) offset[a + 1] = offset[a] + system.body(a).n_free();
  const Eigen::Index n = offset[n_bodies];

  // Block-diagonal stiffness and right-hand side.
  std::vector<Eigen::Triplet<double>> tk;
  Eigen::VectorXd b(n);
  for (size_t a = 0; a < n_bodies; ++a) {
    const auto& K = system.body(a).reduced_stiffness();
    for (int col = 0; col < K.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
        tk.emplace_back(offset[a] + it.row(), offset[a] + it.col(), it.value());
    b.segment(offset[a], system.body(a).n_free()) = system.body(a).reduced_rhs();
  }
  Eigen::SparseMatrix<double> K(n, n);
  K.setFromTriplets(tk.begin(), tk.end());

  // Each pair's gap as an affine function of x.
  std::vector<GlobalPair> gpairs;
  for (const auto& pair : system.pairs()) {
    const size_t s = static_cast<size_t>(pair.slave_body), m = static_cast<size_t>(pair.master_body);
    const auto& cs = system.body(s).constraints();
    const auto& cm = system.body(m).constraints();
    const Eigen::SparseMatrix<double> Bs = pair.Gs * cs.T(), Bm = pair.Gm * cm.T();
    std::vector<Eigen::Triplet<double>> tb;
    for (int r = 0; r < Bs.outerSize(); ++r)
      for (Eigen::SparseMatrix<double>::InnerIterator it(Bs, r); it; ++it) tb.emplace_back(it.row(), offset[s] + it.col(), it.value());
    for (int r = 0; r < Bm.outerSize(); ++r)
      for (Eigen::SparseMatrix<double>::InnerIterator it(Bm, r); it; ++it) tb.emplace_back(it.row(), offset[m] + it.col(), -it.value());
    GlobalPair gp;
    gp.B.resize(pair.n_points(), n);
    gp.B.setFromTriplets(tb.begin(), tb.end());
    gp.d = pair.effective_gap() + pair.Gs * cs.g() - pair.Gm * cm.g();  // shifted by theta lambda under AL
    gp.w_over_theta = pair.weight / pair.theta;
    gpairs.push_back(std::move(gp));
  }

  auto energy = [&](const Eigen::VectorXd& x) {
    double e = 0.5 * x.dot(K * x) - b.dot(x);
    for (const auto& gp : gpairs) {
      const Eigen::VectorXd g = gp.d + gp.B * x;
      for (Eigen::Index q = 0; q < g.size(); ++q)
        if (g[q] < 0) e += 0.5 * gp.w_over_theta[q] * g[q] * g[q];
    }
    return e;
  };
  auto gradient = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd grad = K * x - b;
    for (const auto& gp : gpairs) {
      const Eigen::VectorXd g = gp.d + gp.B * x;
      Eigen::VectorXd f = Eigen::VectorXd::Zero(g.size());
      for (Eigen::Index q = 0; q < g.size(); ++q)
        if (g[q] < 0) f[q] = gp.w_over_theta[q] * g[q];
      grad.noalias() += gp.B.transpose() * f;
    }
    return grad;
  };
  auto to_bodies = [&](const Eigen::VectorXd& x) {
    Displacements u(n_bodies);
    for (size_t a = 0; a < n_bodies; ++a)
      u[a] = system.body(a).constraints().expand(x.segment(offset[a], system.body(a).n_free()));
    return u;
  };

  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<std::vector<char>> active_report;
  std::vector<Eigen::VectorXd> zone(n_bodies);
  {
    const Displacements u0 = to_bodies(x);
    for (size_t a = 0; a < n_bodies; ++a) zone[a] = system.zone_normals(a, u0[a]);
  }
  const double b_norm = std::max(b.norm(), 1e-300);
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> factor;
  const int max_newton = std::max(settings.max_iterations, 1);
  for (int k = 1; k <= max_newton; ++k) {
    if (context.cancel.cancelled()) {
      out.reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    // Newton matrix on the current active set: K + sum B^T W_A B / theta.
    Eigen::SparseMatrix<double> H = K;
    for (const auto& gp : gpairs) {
      const Eigen::VectorXd g = gp.d + gp.B * x;
      Eigen::VectorXd w = Eigen::VectorXd::Zero(g.size());
      for (Eigen::Index q = 0; q < g.size(); ++q)
        if (g[q] < 0) w[q] = gp.w_over_theta[q];
      H += Eigen::SparseMatrix<double>(gp.B.transpose() * w.asDiagonal() * gp.B);
    }
    const Eigen::VectorXd grad = gradient(x);
    factor.compute(H);
    if (factor.info() != Eigen::Success) {
      out.reason = StopReason::error;
      out.message = "monolithic: the Newton matrix could not be factorised";
      break;
    }
    const Eigen::VectorXd step = factor.solve(-grad);
    // Backtracking (Armijo) line search on the convex energy.
    const double e0 = energy(x), slope = grad.dot(step);
    double alpha = 1.0;
    Eigen::VectorXd x_new = x + step;
    for (int ls = 0; ls < 30 && energy(x_new) > e0 + 1e-4 * alpha * slope + 1e-15 * std::abs(e0); ++ls) {
      alpha *= 0.5;
      x_new = x + alpha * step;
    }
    x = x_new;
    const Displacements u = to_bodies(x);
    double paper = 0.0;
    for (size_t a = 0; a < n_bodies; ++a) {
      const Eigen::VectorXd z = system.zone_normals(a, u[a]);
      paper = std::max(paper, relative_change(z, zone[a]));
      zone[a] = z;
    }
    const double residual = gradient(x).norm() / b_norm;
    IterationReport r = system.report(k, u, active_report);
    r.paper_criterion = paper;
    r.fixed_point_residual = residual;  // for Newton: the relative norm of the energy gradient
    r.elapsed_seconds = context.elapsed();
    int changed = 0;
    for (const auto& p : r.pairs) changed += p.changed_points;
    context.observer.on_iteration(r);
    out.history.push_back(std::move(r));
    out.iterations = k;
    const double step_size = alpha * step.norm() / std::max(x.norm(), 1e-300);
    if (k > 1 && changed == 0 && (residual <= 1e-12 || step_size <= 1e-13)) {
      out.converged = true;
      out.reason = StopReason::converged;
      std::ostringstream os;
      os << "Newton converged in " << k << " steps (active set unchanged, gradient " << residual << ")";
      out.message = os.str();
      break;
    }
    if (k == max_newton) {
      out.reason = StopReason::max_iterations;
      out.message = "monolithic: Newton did not settle within max_iterations";
    }
  }
  out.u = to_bodies(x);
  return out;
}

}  // namespace contact::ddm
