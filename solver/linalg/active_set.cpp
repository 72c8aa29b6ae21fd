#include "active_set.hpp"
#include "../common/assert.hpp"
#include "refined_solve.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/Cholesky>
#include <Eigen/UmfPackSupport>

#include <algorithm>
#include <set>
#include <sstream>
#include <vector>

namespace contact::linalg {

namespace {

using Factor = Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower>;

// H restricted to the rows and columns A (sorted or not): H_AA, with the order of A.
SparseMatrix restrict_to(const SparseMatrix& H, const std::vector<Eigen::Index>& A) {
  std::vector<Eigen::Index> position(static_cast<size_t>(H.rows()), -1);
  for (size_t i = 0; i < A.size(); ++i) position[static_cast<size_t>(A[i])] = static_cast<Eigen::Index>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t j = 0; j < A.size(); ++j)
    for (SparseMatrix::InnerIterator it(H, A[j]); it; ++it) {
      const Eigen::Index i = position[static_cast<size_t>(it.row())];
      if (i >= 0) entries.emplace_back(i, static_cast<Eigen::Index>(j), it.value());
    }
  SparseMatrix out(static_cast<Eigen::Index>(A.size()), static_cast<Eigen::Index>(A.size()));
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

// The columns A of G (r x |A|).
SparseMatrix columns_of(const SparseMatrix& G, const std::vector<Eigen::Index>& A) {
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t j = 0; j < A.size(); ++j)
    for (SparseMatrix::InnerIterator it(G, A[j]); it; ++it)
      entries.emplace_back(it.row(), static_cast<Eigen::Index>(j), it.value());
  SparseMatrix out(G.rows(), static_cast<Eigen::Index>(A.size()));
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

// The rows of G that the columns GA do not reach (a floating body with no node in A): zero, relative to the
// largest row, in G_A.
std::vector<Eigen::Index> rows_not_reached(const SparseMatrix& GA) {
  Eigen::VectorXd norm2 = Eigen::VectorXd::Zero(GA.rows());
  for (int col = 0; col < GA.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(GA, col); it; ++it) norm2[it.row()] += it.value() * it.value();
  const double scale = std::max(norm2.maxCoeff(), 1e-300);
  std::vector<Eigen::Index> out;
  for (Eigen::Index i = 0; i < GA.rows(); ++i)
    if (!(norm2[i] > 1e-24 * scale)) out.push_back(i);
  return out;
}

// Up to this many equality rows (a few floating bodies) the Schur complement on alpha is taken dense: r solves
// with H_AA's factor, cheaper than a factorisation of the saddle system when H_AA is dense (two bodies with one
// contact zone); past it, the sparse saddle system.
constexpr Eigen::Index kDenseSchurRows = 48;

// zA (H_AA^-1 rhs on entry) and alpha by the dense Schur complement S = G_A H_AA^-1 G_A^T; false, with
// `unrestrained` filled, when S is singular (a row no node of A reaches: its diagonal vanishes; or a group).
bool solve_by_schur(const Factor& llt, const SparseMatrix& GA, const Eigen::VectorXd& e, Eigen::VectorXd& zA,
                    Eigen::VectorXd& alpha, std::vector<Eigen::Index>& unrestrained) {
  const Eigen::Index r = GA.rows();
  const Eigen::MatrixXd Y = llt.solve(Eigen::MatrixXd(GA.transpose()));  // H_AA^-1 G_A^T
  const Eigen::MatrixXd S = GA * Y;
  const double scale = std::max(S.diagonal().cwiseAbs().maxCoeff(), 1e-300);
  for (Eigen::Index i = 0; i < r; ++i)
    if (!(S(i, i) > 1e-12 * scale)) unrestrained.push_back(i);
  Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  if (!unrestrained.empty() || ldlt.info() != Eigen::Success || ldlt.isNegative() ||
      ldlt.vectorD().cwiseAbs().minCoeff() <= 1e-12 * scale) {
    if (unrestrained.empty())
      for (Eigen::Index i = 0; i < r; ++i) unrestrained.push_back(i);
    return false;
  }
  alpha = ldlt.solve(GA * zA - e);
  zA -= Y * alpha;
  return true;
}

// zA and alpha from the sparse saddle system [H_AA G_A^T; G_A 0] [zA; alpha] = [rhs; e] by LU with a step of
// refinement; false when it is singular to rounding (refined_solve.hpp).
bool solve_saddle(const SparseMatrix& HAA, const SparseMatrix& GA, const Eigen::VectorXd& rhs, const Eigen::VectorXd& e,
                  Eigen::VectorXd& zA, Eigen::VectorXd& alpha) {
  const Eigen::Index na = HAA.rows(), r = GA.rows();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(HAA.nonZeros() + 2 * GA.nonZeros()));
  for (int col = 0; col < HAA.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(HAA, col); it; ++it) entries.emplace_back(it.row(), it.col(), it.value());
  for (int col = 0; col < GA.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(GA, col); it; ++it) {
      entries.emplace_back(na + it.row(), it.col(), it.value());
      entries.emplace_back(it.col(), na + it.row(), it.value());
    }
  SparseMatrix K(na + r, na + r);
  K.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd b(na + r), x;
  b << rhs, e;
  if (!refined_solve<Eigen::UmfPackLU<SparseMatrix>>(K, b, 1, /*strict=*/true, x)) return false;
  zA = x.head(na);
  alpha = x.tail(r);
  return true;
}

// z (and alpha) with h_A = 0 on the index set A, z = 0 elsewhere, and G z = e: H_AA z_A + G_A^T alpha = -g_A,
// G_A z_A = e. Without equalities by the Cholesky factor of H_AA; with a few, by the dense Schur complement on
// alpha; with many, as the sparse saddle system [H_AA G_A^T; G_A 0] by LU (UMFPACK, one refinement step): its cost
// is that of its sparse factor, where the Schur complement (r x r, and H_AA^-1 G_A^T, |A| x r) is dense in the
// number of floating bodies (three rows each: 1,488 at a 22 x 22 wall). `ok` is false when H_AA is not positive
// definite; `unrestrained` receives the rows of G that A leaves without support: a body no node of A touches, or
// every row when the system is singular (a group of bodies A holds by nothing as a whole).
Eigen::VectorXd solve_on(const SparseMatrix& H, const Eigen::VectorXd& g, const std::vector<Eigen::Index>& A,
                         const Equalities& eq, Eigen::VectorXd& alpha, bool& ok,
                         std::vector<Eigen::Index>& unrestrained) {
  Eigen::VectorXd z = Eigen::VectorXd::Zero(g.size());
  ok = true;
  unrestrained.clear();
  const Eigen::Index na = static_cast<Eigen::Index>(A.size()), r = eq.G.rows();
  alpha = Eigen::VectorXd::Zero(r);
  if (na == 0) {
    for (Eigen::Index i = 0; i < r; ++i) unrestrained.push_back(i);
    return z;
  }
  Eigen::VectorXd rhs(na);
  for (Eigen::Index i = 0; i < na; ++i) rhs[i] = -g[A[static_cast<size_t>(i)]];
  const SparseMatrix HAA = restrict_to(H, A);
  Factor llt;
  llt.cholmod().print = 0;  // a failed factorisation is reported by info(), not by CHOLMOD's text on stdout
  llt.compute(HAA);
  if (llt.info() != Eigen::Success) {
    ok = false;
    return z;
  }
  Eigen::VectorXd zA;
  if (r > kDenseSchurRows) {
    const SparseMatrix GA = columns_of(eq.G, A);
    unrestrained = rows_not_reached(GA);
    if (!unrestrained.empty()) return z;
    if (!solve_saddle(HAA, GA, rhs, eq.e, zA, alpha)) {
      for (Eigen::Index i = 0; i < r; ++i) unrestrained.push_back(i);
      return z;
    }
  } else {
    zA = llt.solve(rhs);
    if (r > 0 && !solve_by_schur(llt, columns_of(eq.G, A), eq.e, zA, alpha, unrestrained)) return z;
  }
  for (Eigen::Index i = 0; i < na; ++i) z[A[static_cast<size_t>(i)]] = zA[i];
  return z;
}

}  // namespace

Eigen::VectorXd solve_nonnegative_qp(const SparseMatrix& H, const Eigen::VectorXd& g, int max_steps) {
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
      Eigen::VectorXd unused_alpha;
      std::vector<Eigen::Index> unused_rows;
      const Eigen::VectorXd s = solve_on(H, g, P, Equalities{}, unused_alpha, ok, unused_rows);
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

std::vector<Eigen::Index> coarse_unknowns(const std::vector<int>& line) {
  const auto n = static_cast<Eigen::Index>(line.size());
  std::vector<Eigen::Index> keep;
  for (Eigen::Index j = 0; j < n; ++j) {
    const bool first = j == 0 || line[static_cast<size_t>(j)] != line[static_cast<size_t>(j) - 1];
    const bool last = j + 1 == n || line[static_cast<size_t>(j) + 1] != line[static_cast<size_t>(j)];
    if (first || last || (!keep.empty() && j - keep.back() >= 2)) keep.push_back(j);
  }
  return keep;
}

Eigen::VectorXd nested_initial_guess(const SparseMatrix& H, const Eigen::VectorXd& g, const std::vector<int>& line,
                                     const Eigen::VectorXd& position, const Equalities& equalities,
                                     std::vector<std::pair<Eigen::Index, int>>* levels, Eigen::Index coarsest) {
  const Eigen::Index n = g.size();
  if (n <= coarsest) return Eigen::VectorXd::Zero(n);
  const std::vector<Eigen::Index> keep = coarse_unknowns(line);
  const Eigen::Index nc = static_cast<Eigen::Index>(keep.size());
  if (nc >= n) return Eigen::VectorXd::Zero(n);
  // P: n x nc, identity on the kept unknowns, linear interpolation between them (sparse: two entries a row).
  std::vector<Eigen::Triplet<double>> p_entries;
  for (Eigen::Index c = 0; c < nc; ++c) {
    p_entries.emplace_back(keep[static_cast<size_t>(c)], c, 1.0);
    if (c + 1 == nc || line[static_cast<size_t>(keep[static_cast<size_t>(c) + 1])] !=
                           line[static_cast<size_t>(keep[static_cast<size_t>(c)])])
      continue;
    const Eigen::Index a = keep[static_cast<size_t>(c)], b = keep[static_cast<size_t>(c) + 1];
    for (Eigen::Index j = a + 1; j < b; ++j) {
      const double t = (position[j] - position[a]) / (position[b] - position[a]);
      p_entries.emplace_back(j, c, 1 - t);
      p_entries.emplace_back(j, c + 1, t);
    }
  }
  SparseMatrix P(n, nc);
  P.setFromTriplets(p_entries.begin(), p_entries.end());
  std::vector<int> line_c(static_cast<size_t>(nc));
  Eigen::VectorXd position_c(nc);
  for (Eigen::Index c = 0; c < nc; ++c) {
    line_c[static_cast<size_t>(c)] = line[static_cast<size_t>(keep[static_cast<size_t>(c)])];
    position_c[c] = position[keep[static_cast<size_t>(c)]];
  }
  const SparseMatrix Pt = P.transpose();
  const SparseMatrix Hc = Pt * H * P;
  const Eigen::VectorXd gc = Pt * g;
  Equalities coarse_eq;
  if (!equalities.empty()) coarse_eq = Equalities{SparseMatrix(equalities.G * P), equalities.e};
  const size_t at = levels ? levels->size() : 0;
  if (levels) levels->emplace_back(nc, 0);
  const Eigen::VectorXd guess = nested_initial_guess(Hc, gc, line_c, position_c, coarse_eq, levels, coarsest);
  const QpSolution coarse = solve_active_set(
      Hc, gc, 50, [](const Eigen::VectorXd&, const Eigen::VectorXd&, const ActiveSetStep&) { return false; },
      guess.cwiseAbs().maxCoeff() > 0 ? &guess : nullptr, coarse_eq);
  if (levels) (*levels)[at].second = static_cast<int>(coarse.report.iterations);
  if (!coarse.report.converged()) return Eigen::VectorXd::Zero(n);  // no guess: the fine problem starts as without one
  return P * coarse.z.cwiseMax(0.0);
}

namespace {

// The primal-dual active set in its phases: the first set, one step (solve on the set, gaps, next set), the
// settling test, and the QP method should the sets cycle.
class PrimalDualActiveSet {
 public:
  PrimalDualActiveSet(const SparseMatrix& H, const Eigen::VectorXd& g, const Equalities& eq)
      : H_(H), g_(g), eq_(eq), n_(g.size()), c_over_D_(H.diagonal().cwiseInverse()) {}  // c_j / D_j = 1 / H_jj

  QpSolution run(int max_steps, const StepCallback& on_step, const Eigen::VectorXd* z0);

 private:
  std::vector<char> predict(const Eigen::VectorXd& z, const Eigen::VectorXd& h) const {
    std::vector<char> a(static_cast<size_t>(n_), 0);
    for (Eigen::Index j = 0; j < n_; ++j) a[static_cast<size_t>(j)] = z[j] - c_over_D_[j] * h[j] > 0;
    return a;
  }
  double complementarity(const Eigen::VectorXd& z, const Eigen::VectorXd& h) const {
    Eigen::VectorXd C(n_);
    for (Eigen::Index j = 0; j < n_; ++j) C[j] = z[j] - std::max(0.0, z[j] - c_over_D_[j] * h[j]);
    return C.norm() / std::max(z.norm(), 1e-300);
  }
  Eigen::VectorXd gap(const Eigen::VectorXd& z, const Eigen::VectorXd& alpha) const {
    Eigen::VectorXd h = g_ + H_ * z;
    if (!eq_.empty()) h.noalias() += eq_.G.transpose() * alpha;
    return h;
  }
  // The first active set. A floating body's position is part of the answer (alpha), so with equalities the gaps of
  // a guess z0 predict nothing: start from the nodes the guess presses, or from every node without a guess.
  std::vector<char> first_set(const Eigen::VectorXd* z0) const {
    const bool guessed = z0 && z0->size() == n_;
    const Eigen::VectorXd z = guessed ? *z0 : Eigen::VectorXd::Zero(n_);
    if (eq_.empty()) return predict(z, g_ + H_ * z);
    if (!guessed) return std::vector<char>(static_cast<size_t>(n_), 1);
    std::vector<char> active(static_cast<size_t>(n_));
    for (Eigen::Index j = 0; j < n_; ++j) active[static_cast<size_t>(j)] = (*z0)[j] > 0;
    return active;
  }
  // Solves on `active`, fills out's z, alpha, h and the step's report; `next` receives the predicted set. False
  // when the step cannot be taken (out.report.message says why).
  bool step(int k, const std::vector<char>& active, QpSolution& out, ActiveSetStep& report,
            std::vector<char>& next) const {
    std::vector<Eigen::Index> A;
    for (Eigen::Index j = 0; j < n_; ++j)
      if (active[static_cast<size_t>(j)]) A.push_back(j);
    bool ok = true;
    Eigen::VectorXd alpha;
    const Eigen::VectorXd z = solve_on(H_, g_, A, eq_, alpha, ok, out.unrestrained);
    if (!ok) {
      out.report.stop = SolveStop::singular;
      out.report.message = "the active-set system is not positive definite";
      return false;
    }
    if (!out.unrestrained.empty()) {
      out.report.stop = SolveStop::singular;
      out.report.message = "the contact nodes in contact do not hold every floating body";
      return false;
    }
    const Eigen::VectorXd h = gap(z, alpha);
    next = predict(z, h);
    report.step = k;
    report.active = static_cast<int>(A.size());
    for (Eigen::Index j = 0; j < n_; ++j)
      report.changes += next[static_cast<size_t>(j)] != active[static_cast<size_t>(j)];
    report.complementarity = complementarity(z, h);
    out.z = z;
    out.alpha = alpha;
    out.h = h;
    out.report.iterations = k;
    return true;
  }
  void fallback(const StepCallback& on_step, QpSolution& out) const;

  const SparseMatrix& H_;
  const Eigen::VectorXd& g_;
  const Equalities& eq_;
  const Eigen::Index n_;
  const Eigen::VectorXd c_over_D_;
};

// Cycling or max_steps: the primal active-set QP method, which terminates.
void PrimalDualActiveSet::fallback(const StepCallback& on_step, QpSolution& out) const {
  out.used_fallback = true;
  out.z = solve_nonnegative_qp(H_, g_);
  out.h = g_ + H_ * out.z;
  ActiveSetStep step;
  step.step = static_cast<int>(out.report.iterations) + 1;
  for (Eigen::Index j = 0; j < n_; ++j) step.active += out.z[j] > 0;
  step.complementarity = complementarity(out.z, out.h);
  out.report.iterations = step.step;
  if (on_step(out.z, out.h, step)) {
    out.report.stop = SolveStop::cancelled;
    out.report.message = "cancelled";
    return;
  }
  out.report.stop = step.complementarity <= 1e-10 ? SolveStop::converged : SolveStop::max_iterations;
  std::ostringstream os;
  os << "the primal-dual active set cycled or did not settle; the active-set QP method "
     << (out.report.converged() ? "solved" : "did not solve") << " the interface problem (complementarity "
     << step.complementarity << ", " << step.active << " of " << n_ << " contact nodes in contact)";
  out.report.message = os.str();
}

QpSolution PrimalDualActiveSet::run(int max_steps, const StepCallback& on_step, const Eigen::VectorXd* z0) {
  QpSolution out;
  out.alpha = Eigen::VectorXd::Zero(eq_.G.rows());
  out.z = z0 && z0->size() == n_ ? *z0 : Eigen::VectorXd::Zero(n_);
  out.h = g_ + H_ * out.z;
  if (n_ == 0 && eq_.empty()) {
    out.report.stop = SolveStop::converged;
    out.report.message = "no contact nodes";
    return out;
  }
  std::vector<char> active = first_set(z0);
  std::set<std::vector<char>> seen;
  for (int k = 1; k <= max_steps; ++k) {
    seen.insert(active);
    ActiveSetStep report;
    std::vector<char> next;
    if (!step(k, active, out, report, next)) return out;
    if (on_step(out.z, out.h, report)) {
      out.report.stop = SolveStop::cancelled;
      out.report.message = "cancelled";
      return out;
    }
    // Settled: the set repeats, or the complementarity function vanishes to round-off (a grazing node, with
    // z = 0 and h = 0 up to rounding, may flip without changing the solution).
    if (report.changes == 0 || report.complementarity <= 1e-13) {
      out.report.stop = SolveStop::converged;
      std::ostringstream os;
      os << "active set settled (" << report.active << " of " << n_ << " contact nodes in contact)";
      out.report.message = os.str();
      return out;
    }
    if (seen.count(next)) break;  // a cycle: hand over to the QP method
    active = std::move(next);
  }
  if (!eq_.empty()) {
    out.report.message = "the primal-dual active set cycled or did not settle with floating bodies";
    return out;
  }
  fallback(on_step, out);
  return out;
}

QpSolution solve_active_set_on(const SparseMatrix& H, const Eigen::VectorXd& g, int max_steps,
                               const StepCallback& on_step, const Eigen::VectorXd* z0, const Equalities& eq) {
  return PrimalDualActiveSet(H, g, eq).run(max_steps, on_step, z0);
}

}  // namespace

QpSolution solve_active_set(const SparseMatrix& H, const Eigen::VectorXd& g, int max_steps, const StepCallback& on_step,
                            const Eigen::VectorXd* z0, const Equalities& eq) {
  CONTACT_ASSERT_SIZE(H.rows(), g.size(), "H");
  CONTACT_ASSERT_SIZE(H.cols(), g.size(), "H");
  if (z0) CONTACT_ASSERT_SIZE(z0->size(), g.size(), "the start z0");
  if (!eq.empty()) CONTACT_ASSERT_SIZE(eq.G.cols(), g.size(), "G");
  if (eq.empty()) return solve_active_set_on(H, g, max_steps, on_step, z0, eq);
  // With floating bodies H = B K^+ B^T uses a generalised inverse that fixes a few dofs per body; where those
  // dofs lie on the contact (a body of one or two cells across, contact on two sides) the compliance of a contact
  // node can vanish, and H_AA is singular although the problem is well posed: H is definite only on ker G_A.
  // Solved instead with H + rho G^T G and g - rho G^T e, which has the same solution (the added terms are
  // rho G^T (G z - e) = 0 wherever G z = e) and the same gaps h, and is definite exactly where the problem is.
  const SparseMatrix Gt = eq.G.transpose();
  const SparseMatrix GtG = Gt * eq.G;
  const double h_scale = H.rows() ? H.diagonal().cwiseAbs().maxCoeff() : 0.0;
  const double g_scale = GtG.rows() ? GtG.diagonal().maxCoeff() : 0.0;
  if (!(h_scale > 0) || !(g_scale > 0)) return solve_active_set_on(H, g, max_steps, on_step, z0, eq);
  const double rho = h_scale / g_scale;
  const SparseMatrix H_rho = H + rho * GtG;
  const Eigen::VectorXd g_rho = g - rho * (Gt * eq.e);
  return solve_active_set_on(H_rho, g_rho, max_steps, on_step, z0, eq);
}

}  // namespace contact::linalg
