#include "friction_nested.hpp"

#include "refined_solve.hpp"

#include <Eigen/UmfPackSupport>

#include <algorithm>

namespace contact::linalg {

namespace {

using Rows = std::vector<Eigen::Index>;

// Rows `rows` of a column-major sparse matrix A (in that order).
SparseMatrix select_rows(const SparseMatrix& A, const Rows& rows) {
  std::vector<Eigen::Index> position(static_cast<size_t>(A.rows()), -1);
  for (size_t i = 0; i < rows.size(); ++i) position[static_cast<size_t>(rows[i])] = static_cast<Eigen::Index>(i);
  std::vector<Eigen::Triplet<double>> entries;
  for (int col = 0; col < A.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(A, col); it; ++it)
      if (const Eigen::Index i = position[static_cast<size_t>(it.row())]; i >= 0)
        entries.emplace_back(i, col, it.value());
  SparseMatrix out(static_cast<Eigen::Index>(rows.size()), A.cols());
  out.setFromTriplets(entries.begin(), entries.end());
  return out;
}

// A coarser level: the prolongation P (fine x coarse) and the coarse problem's rows, lines and positions.
struct Coarsening {
  SparseMatrix P;
  std::vector<FrictionRow> rows;
  std::vector<int> line;
  Eigen::VectorXd position;
  Eigen::Index m = 0, n = 0;  // coarse normal unknowns, all coarse unknowns
};

Coarsening coarsen(const FrictionLevel& level) {
  Coarsening c;
  const Rows keep = coarse_unknowns(level.line);  // normal unknowns: level.line has one entry per normal row
  c.m = static_cast<Eigen::Index>(keep.size());
  // Each fine normal unknown's friction row (if any), and the coarse unknowns: the kept normals, then one
  // tangential unknown per kept normal that has a friction row.
  std::vector<long> row_of(static_cast<size_t>(level.m), -1);
  for (size_t t = 0; t < level.rows.size(); ++t)
    row_of[static_cast<size_t>(level.rows[t].normal)] = static_cast<long>(t);
  std::vector<Eigen::Index> coarse_tangential(keep.size(), -1);
  c.n = c.m;
  for (size_t k = 0; k < keep.size(); ++k)
    if (const long t = row_of[static_cast<size_t>(keep[k])]; t >= 0) {
      coarse_tangential[k] = c.n++;
      FrictionRow r = level.rows[static_cast<size_t>(t)];
      r.normal = static_cast<Eigen::Index>(k);
      r.tangential = coarse_tangential[k];
      c.rows.push_back(r);
    }
  c.line.resize(keep.size());
  c.position.resize(c.m);
  for (size_t k = 0; k < keep.size(); ++k) {
    c.line[k] = level.line[static_cast<size_t>(keep[k])];
    c.position[static_cast<Eigen::Index>(k)] = level.position[keep[k]];
  }
  // P: the same weights for a node's normal and tangential multiplier (a kept node: itself; another: linear in
  // arc length between the kept nodes around it on its line).
  std::vector<Eigen::Triplet<double>> entries;
  auto put = [&](Eigen::Index fine, size_t k, double w) {
    entries.emplace_back(fine, static_cast<Eigen::Index>(k), w);
    const long t = row_of[static_cast<size_t>(fine)];
    if (t >= 0 && coarse_tangential[k] >= 0)
      entries.emplace_back(level.rows[static_cast<size_t>(t)].tangential, coarse_tangential[k], w);
  };
  for (size_t k = 0; k < keep.size(); ++k) {
    put(keep[k], k, 1.0);
    if (k + 1 == keep.size() || c.line[k + 1] != c.line[k]) continue;
    const Eigen::Index a = keep[k], b = keep[k + 1];
    for (Eigen::Index j = a + 1; j < b; ++j) {
      const double s = (level.position[j] - level.position[a]) / (level.position[b] - level.position[a]);
      put(j, k, 1 - s);
      put(j, k + 1, s);
    }
  }
  c.P.resize(level.F.rows(), c.n);
  c.P.setFromTriplets(entries.begin(), entries.end());
  return c;
}

// A level's sets without a coarser guess: the frictionless normal active set (with the equilibrium normal
// pressures can meet), every node in contact sticking (what the fine solver starts from without a guess).
bool sticking_sets(const FrictionLevel& level, const std::vector<char>& mask, FrictionSets& sets) {
  const SparseMatrix Fnn = level.F.topLeftCorner(level.m, level.m);
  const QpSolution normal = solve_active_set(
      Fnn, level.g.head(level.m), 100,
      [](const Eigen::VectorXd&, const Eigen::VectorXd&, const ActiveSetStep&) { return false; }, nullptr,
      normal_equalities(level.eq, level.m));
  if (!normal.report.converged()) return false;
  sets.active.assign(mask.size(), 0);
  for (Eigen::Index j = 0; j < level.m; ++j) sets.active[static_cast<size_t>(j)] = normal.z[j] > 0;
  stick_where_in_contact(sets, level.rows);
  return true;
}

// The friction Newton on one level from `sets`; false if it does not settle within max_steps.
bool newton_on_level(const FrictionLevel& level, const Eigen::VectorXd& c, const std::vector<char>& mask,
                     FrictionSets sets, int max_steps, FrictionIterate& solution, int& steps) {
  const FrictionNewtonProblem problem{level.rows, mask, c, [&](const FrictionParametrization& p, FrictionIterate& x) {
                                        return solve_on_friction_sets(level.F, level.g, level.eq, p, x);
                                      }};
  FrictionNewtonSettings settings;
  settings.max_steps = max_steps;
  settings.tolerance = 0.0;  // the sets repeating, as the fine level's start needs them
  const FrictionNewtonResult r = friction_newton(problem, std::move(sets), settings);
  steps = static_cast<int>(r.report.iterations);
  solution = r.iterate;
  return r.report.converged();
}

// M y = rhs by UMFPACK with a step of refinement (refined_solve.hpp); false when M is singular or so nearly that
// the refined solution does not solve it.
bool solve_refined(const SparseMatrix& M, const Eigen::VectorXd& rhs, Eigen::VectorXd& y) {
  return refined_solve<Eigen::UmfPackLU<SparseMatrix>>(M, rhs, 1, /*strict=*/true, y);
}

// [R F P  R G^T; G P  0] [y; alpha] = [-R (g + F lambda0); e - G lambda0], by UMFPACK; false when singular.
bool solve_sets_system(const SparseMatrix& F, const Equalities& eq, const FrictionParametrization& p,
                       const Eigen::VectorXd& g, Eigen::VectorXd& y) {
  const Eigen::Index na = static_cast<Eigen::Index>(p.rows.size()), r = eq.G.rows();
  const SparseMatrix RFP = select_rows(SparseMatrix(F * p.P), p.rows);
  const SparseMatrix RGt = r > 0 ? select_rows(SparseMatrix(eq.G.transpose()), p.rows) : SparseMatrix(na, 0);
  const SparseMatrix GP = r > 0 ? SparseMatrix(eq.G * p.P) : SparseMatrix(0, na);
  std::vector<Eigen::Triplet<double>> entries;
  auto put = [&](const SparseMatrix& A, Eigen::Index row0, Eigen::Index col0) {
    for (int col = 0; col < A.outerSize(); ++col)
      for (SparseMatrix::InnerIterator it(A, col); it; ++it)
        entries.emplace_back(row0 + it.row(), col0 + col, it.value());
  };
  put(RFP, 0, 0);
  put(RGt, 0, na);
  put(GP, na, 0);
  SparseMatrix M(na + r, na + r);
  M.setFromTriplets(entries.begin(), entries.end());
  M.makeCompressed();
  Eigen::VectorXd rhs(na + r);
  const Eigen::VectorXd h0 = g + F * p.lambda0;
  for (Eigen::Index i = 0; i < na; ++i) rhs[i] = -h0[p.rows[static_cast<size_t>(i)]];
  if (r > 0) rhs.tail(r) = eq.e - eq.G * p.lambda0;
  if (solve_refined(M, rhs, y)) return true;
  if (r == 0) return false;
  // Singular: a floating body (or a group) whose rigid motion no free multiplier fixes, the rows of G P dependent.
  // Where the loads on it balance with the tractions its sets prescribe (a brick whose bed joints above and below
  // both slip at mu times the same normal force: its slip is indeterminate, every value an equilibrium), the
  // system is consistent and the solution with the least rigid motion along the free directions is as good an
  // answer as any: regularised, -eps I in the equilibrium block, and taken only if the equalities still hold (the
  // regularisation did not have to push), otherwise the sets are singular indeed (the body would slide away).
  // The rows' squared norms by one pass over the columns (row(i) of a column-major sparse matrix is a strided
  // view whose reductions Eigen does not support: it crashed on a Cattaneo-Mindlin job of 325 x 10 cells).
  Eigen::VectorXd row2 = Eigen::VectorXd::Zero(GP.rows());
  for (int col = 0; col < GP.outerSize(); ++col)
    for (SparseMatrix::InnerIterator it(GP, col); it; ++it) row2[it.row()] += it.value() * it.value();
  double gp2 = row2.size() ? row2.maxCoeff() : 0.0, f = 0;
  for (Eigen::Index i = 0; i < na; ++i) f = std::max(f, std::abs(RFP.coeff(i, i)));
  if (!(gp2 > 0) || !(f > 0)) return false;
  const double eps = 1e-10 * gp2 / f;
  for (Eigen::Index i = 0; i < r; ++i) entries.emplace_back(na + i, na + i, -eps);
  SparseMatrix Me(na + r, na + r);
  Me.setFromTriplets(entries.begin(), entries.end());
  // Not refined on the true system: that would move the free direction by rounding over eps (the rigid motion the
  // regularisation keeps least); the held bodies' equalities are off by eps alpha, which the test below bounds.
  if (!solve_refined(Me, rhs, y)) return false;
  const Eigen::VectorXd residual = M * y - rhs;
  return residual.tail(r).norm() <= 1e-9 * std::max(rhs.tail(r).norm(), 1e-300) &&
         residual.head(na).norm() <= 1e-9 * std::max(rhs.head(na).norm(), 1e-300);
}

}  // namespace

Equalities normal_equalities(const Equalities& all, Eigen::Index m) {
  if (all.empty()) return all;
  const SparseMatrix Gn = all.G.leftCols(m);
  Rows keep;
  const Eigen::VectorXd normal_part = (Gn.cwiseAbs2() * Eigen::VectorXd::Ones(m)).cwiseSqrt();
  const Eigen::VectorXd whole = (all.G.cwiseAbs2() * Eigen::VectorXd::Ones(all.G.cols())).cwiseSqrt();
  for (Eigen::Index i = 0; i < Gn.rows(); ++i)
    if (normal_part[i] > 1e-8 * whole[i]) keep.push_back(i);
  Equalities out;
  out.G = select_rows(Gn, keep);
  out.e.resize(static_cast<Eigen::Index>(keep.size()));
  for (size_t i = 0; i < keep.size(); ++i) out.e[static_cast<Eigen::Index>(i)] = all.e[keep[i]];
  return out;
}

bool solve_on_friction_sets(const SparseMatrix& F, const Eigen::VectorXd& g, const Equalities& eq,
                            const FrictionParametrization& p, FrictionIterate& x) {
  const Eigen::Index na = static_cast<Eigen::Index>(p.rows.size()), r = eq.G.rows();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(na + r);
  if (na + r > 0) {
    if (!solve_sets_system(F, eq, p, g, y)) return false;
  }
  x.lambda = p.P * y.head(na) + p.lambda0;
  x.other = y.tail(r);
  x.h = g + F * x.lambda;
  if (r > 0) x.h += eq.G.transpose() * x.other;
  return true;
}

Eigen::VectorXd friction_scaling(const SparseMatrix& F) {
  const Eigen::VectorXd diagonal = F.diagonal();
  const double dmax = diagonal.size() ? diagonal.cwiseAbs().maxCoeff() : 0.0;
  Eigen::VectorXd c(diagonal.size());
  for (Eigen::Index j = 0; j < c.size(); ++j) c[j] = 1.0 / std::max(diagonal[j], 1e-12 * dmax + 1e-300);
  return c;
}

bool nested_friction_sets(const FrictionLevel& level, FrictionSets& sets, std::vector<int>* coarse_steps,
                          Eigen::Index coarsest) {
  if (level.m <= coarsest || level.rows.empty()) return false;
  const Coarsening coarse = coarsen(level);
  if (coarse.m >= level.m) return false;
  const SparseMatrix Pt = coarse.P.transpose();
  const SparseMatrix Fc = Pt * level.F * coarse.P;
  const Eigen::VectorXd gc = Pt * level.g;
  // G P (no rows without floating bodies, but always as many columns as unknowns).
  const Equalities eqc{
      level.eq.G.cols() == level.F.rows() ? SparseMatrix(level.eq.G * coarse.P) : SparseMatrix(0, coarse.n),
      level.eq.G.cols() == level.F.rows() ? level.eq.e : Eigen::VectorXd(0)};
  const std::vector<char> mask = tangential_mask(coarse.n, coarse.rows);
  const FrictionLevel coarse_level{Fc, gc, eqc, coarse.rows, mask, coarse.m, coarse.line, coarse.position};
  const size_t at = coarse_steps ? coarse_steps->size() : 0;
  if (coarse_steps) coarse_steps->push_back(0);
  FrictionSets start;
  if (!nested_friction_sets(coarse_level, start, coarse_steps, coarsest) && !sticking_sets(coarse_level, mask, start))
    return false;
  FrictionIterate solution;
  int steps = 0;
  const bool settled = newton_on_level(coarse_level, friction_scaling(Fc), mask, start, 30, solution, steps);
  if (coarse_steps) (*coarse_steps)[at] = steps;
  if (!settled) return false;
  // The fine sets predicted from the prolonged multipliers and the fine gaps and slips they give.
  const Eigen::VectorXd lambda = coarse.P * solution.lambda;
  Eigen::VectorXd h = level.g + level.F * lambda;
  if (solution.other.size() > 0) h += level.eq.G.transpose() * solution.other;
  sets = predict_friction_sets(lambda, h, friction_scaling(level.F), level.rows, level.mask);
  return true;
}

}  // namespace contact::linalg
