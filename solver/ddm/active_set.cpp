#include "active_set.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <set>
#include <sstream>
#include <vector>

namespace contact::ddm {

namespace {

// z with h_A = 0 on the index set A and z = 0 elsewhere: H_AA z_A = -g_A.
Eigen::VectorXd solve_on(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const std::vector<Eigen::Index>& A,
                         bool& ok) {
  Eigen::VectorXd z = Eigen::VectorXd::Zero(g.size());
  ok = true;
  if (A.empty()) return z;
  const Eigen::Index na = static_cast<Eigen::Index>(A.size());
  Eigen::MatrixXd HA(na, na);
  Eigen::VectorXd rhs(na);
  for (Eigen::Index i = 0; i < na; ++i) {
    for (Eigen::Index j = 0; j < na; ++j) HA(i, j) = H(A[i], A[j]);
    rhs[i] = -g[A[i]];
  }
  Eigen::LLT<Eigen::MatrixXd> llt(HA);
  if (llt.info() != Eigen::Success) {
    ok = false;
    return z;
  }
  const Eigen::VectorXd zA = llt.solve(rhs);
  for (Eigen::Index i = 0; i < na; ++i) z[A[i]] = zA[i];
  return z;
}

}  // namespace

Eigen::VectorXd solve_nonnegative_qp(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, int max_steps) {
  const Eigen::Index n = g.size();
  if (max_steps <= 0) max_steps = static_cast<int>(10 * n + 10);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n);
  std::vector<char> passive(static_cast<size_t>(n), 0);
  const double scale = std::max(g.cwiseAbs().maxCoeff(), 1e-300);
  for (int outer = 0; outer < max_steps; ++outer) {
    const Eigen::VectorXd w = -(g + H * z);  // the negative gradient
    Eigen::Index best = -1;
    double best_w = 1e-13 * scale;
    for (Eigen::Index j = 0; j < n; ++j)
      if (!passive[static_cast<size_t>(j)] && w[j] > best_w) {
        best_w = w[j];
        best = j;
      }
    if (best < 0) break;  // KKT: gradient >= 0 on the bound, 0 on the passive set
    passive[static_cast<size_t>(best)] = 1;
    for (int inner = 0; inner <= n; ++inner) {
      std::vector<Eigen::Index> P;
      for (Eigen::Index j = 0; j < n; ++j)
        if (passive[static_cast<size_t>(j)]) P.push_back(j);
      bool ok = true;
      const Eigen::VectorXd s = solve_on(H, g, P, ok);
      if (!ok) return z;
      bool feasible = true;
      for (Eigen::Index j : P) feasible = feasible && s[j] > 0;
      if (feasible) {
        z = s;
        break;
      }
      // Step from z towards s as far as z stays >= 0; the variables that reach 0 leave the passive set.
      double alpha = 1.0;
      for (Eigen::Index j : P)
        if (s[j] <= 0) alpha = std::min(alpha, z[j] / (z[j] - s[j]));
      z += alpha * (s - z);
      for (Eigen::Index j : P)
        if (z[j] <= 1e-15 * scale) {
          z[j] = 0;
          passive[static_cast<size_t>(j)] = 0;
        }
    }
  }
  return z;
}

Eigen::VectorXd nested_initial_guess(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const std::vector<int>& line,
                                     const Eigen::VectorXd& position,
                                     std::vector<std::pair<Eigen::Index, int>>* levels, Eigen::Index coarsest) {
  const Eigen::Index n = g.size();
  if (n <= coarsest) return Eigen::VectorXd::Zero(n);
  // Coarse unknowns: every other one of each line, its first and last always.
  std::vector<Eigen::Index> keep;
  for (Eigen::Index j = 0; j < n; ++j) {
    const bool first = j == 0 || line[static_cast<size_t>(j)] != line[static_cast<size_t>(j) - 1];
    const bool last = j + 1 == n || line[static_cast<size_t>(j) + 1] != line[static_cast<size_t>(j)];
    if (first || last || (!keep.empty() && j - keep.back() >= 2)) keep.push_back(j);
  }
  const Eigen::Index nc = static_cast<Eigen::Index>(keep.size());
  if (nc >= n) return Eigen::VectorXd::Zero(n);
  // P: n x nc, identity on the kept unknowns, linear interpolation between them.
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, nc);
  for (Eigen::Index c = 0; c < nc; ++c) {
    P(keep[static_cast<size_t>(c)], c) = 1.0;
    if (c + 1 == nc || line[static_cast<size_t>(keep[static_cast<size_t>(c) + 1])] != line[static_cast<size_t>(keep[static_cast<size_t>(c)])]) continue;
    const Eigen::Index a = keep[static_cast<size_t>(c)], b = keep[static_cast<size_t>(c) + 1];
    for (Eigen::Index j = a + 1; j < b; ++j) {
      const double t = (position[j] - position[a]) / (position[b] - position[a]);
      P(j, c) = 1 - t;
      P(j, c + 1) = t;
    }
  }
  std::vector<int> line_c(static_cast<size_t>(nc));
  Eigen::VectorXd position_c(nc);
  for (Eigen::Index c = 0; c < nc; ++c) {
    line_c[static_cast<size_t>(c)] = line[static_cast<size_t>(keep[static_cast<size_t>(c)])];
    position_c[c] = position[keep[static_cast<size_t>(c)]];
  }
  const Eigen::MatrixXd Hc = P.transpose() * H * P;
  const Eigen::VectorXd gc = P.transpose() * g;
  const size_t at = levels ? levels->size() : 0;
  if (levels) levels->emplace_back(nc, 0);
  const Eigen::VectorXd guess = nested_initial_guess(Hc, gc, line_c, position_c, levels, coarsest);
  const ActiveSetResult coarse =
      solve_active_set(Hc, gc, 50, [](const Eigen::VectorXd&, const Eigen::VectorXd&, const ActiveSetStep&) { return true; },
                       guess.cwiseAbs().maxCoeff() > 0 ? &guess : nullptr);
  if (levels) (*levels)[at].second = coarse.steps;
  return P * coarse.z.cwiseMax(0.0);
}

ActiveSetResult solve_active_set(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, int max_steps,
                                 const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&,
                                                          const ActiveSetStep&)>& on_step,
                                 const Eigen::VectorXd* z0) {
  ActiveSetResult out;
  const Eigen::Index n = g.size();
  const Eigen::VectorXd c_over_D = H.diagonal().cwiseInverse();  // c_j / D_j = 1 / H_jj
  auto predict = [&](const Eigen::VectorXd& z, const Eigen::VectorXd& h) {
    std::vector<char> a(static_cast<size_t>(n), 0);
    for (Eigen::Index j = 0; j < n; ++j) a[static_cast<size_t>(j)] = z[j] - c_over_D[j] * h[j] > 0;
    return a;
  };
  auto complementarity = [&](const Eigen::VectorXd& z, const Eigen::VectorXd& h) {
    Eigen::VectorXd C(n);
    for (Eigen::Index j = 0; j < n; ++j) C[j] = z[j] - std::max(0.0, z[j] - c_over_D[j] * h[j]);
    return C.norm() / std::max(z.norm(), 1e-300);
  };

  Eigen::VectorXd z = z0 && z0->size() == n ? *z0 : Eigen::VectorXd::Zero(n);
  Eigen::VectorXd h = g + H * z;
  std::vector<char> active = predict(z, h);
  std::set<std::vector<char>> seen;
  out.z = z;
  out.h = h;
  if (n == 0) {
    out.converged = true;
    out.message = "no contact nodes";
    return out;
  }
  for (int k = 1; k <= max_steps; ++k) {
    seen.insert(active);
    std::vector<Eigen::Index> A;
    for (Eigen::Index j = 0; j < n; ++j)
      if (active[static_cast<size_t>(j)]) A.push_back(j);
    bool ok = true;
    z = solve_on(H, g, A, ok);
    if (!ok) {
      out.message = "the active-set system is not positive definite";
      return out;
    }
    h = g + H * z;
    std::vector<char> next = predict(z, h);
    ActiveSetStep step;
    step.step = k;
    step.active = static_cast<int>(A.size());
    for (Eigen::Index j = 0; j < n; ++j) step.changes += next[static_cast<size_t>(j)] != active[static_cast<size_t>(j)];
    step.complementarity = complementarity(z, h);
    out.z = z;
    out.h = h;
    out.steps = k;
    if (!on_step(z, h, step)) {
      out.cancelled = true;
      out.message = "cancelled";
      return out;
    }
    // Settled: the set repeats, or the complementarity function vanishes to round-off (a grazing node, with
    // z = 0 and h = 0 up to rounding, may flip without changing the solution).
    if (step.changes == 0 || step.complementarity <= 1e-13) {
      out.converged = true;
      std::ostringstream os;
      os << "active set settled (" << A.size() << " of " << n << " contact nodes in contact)";
      out.message = os.str();
      return out;
    }
    if (seen.count(next)) break;  // a cycle: hand over to the QP method
    active = std::move(next);
  }
  // Cycling or max_steps: the primal active-set QP method, which terminates.
  out.used_fallback = true;
  out.z = solve_nonnegative_qp(H, g);
  out.h = g + H * out.z;
  ActiveSetStep step;
  step.step = out.steps + 1;
  for (Eigen::Index j = 0; j < n; ++j) step.active += out.z[j] > 0;
  step.complementarity = complementarity(out.z, out.h);
  out.steps = step.step;
  if (!on_step(out.z, out.h, step)) {
    out.cancelled = true;
    out.message = "cancelled";
    return out;
  }
  out.converged = step.complementarity <= 1e-10;
  std::ostringstream os;
  os << "the primal-dual active set cycled or did not settle; the active-set QP method "
     << (out.converged ? "solved" : "did not solve") << " the interface problem (complementarity "
     << step.complementarity << ", " << step.active << " of " << n << " contact nodes in contact)";
  out.message = os.str();
  return out;
}

}  // namespace contact::ddm
