// MPRGP with box constraints l <= x <= u (solver/linalg/mprgp.hpp) on matrices alone: random SPD problems against
// an independent solution, the enumeration of every assignment of the unknowns to {lower bound, upper bound,
// free} (3^n linear solves; the KKT conditions pick the one solution of the strictly convex QP), and the
// one-sided case unchanged by an absent or infinite upper bound.
#include "linalg/mprgp.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace contact;

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

struct BoxProblem {
  Eigen::MatrixXd A;
  Eigen::VectorXd b, l, u;
};

// A random SPD matrix with a spread spectrum, a right-hand side that pushes many unknowns onto either bound, and
// bounds of every kind: two-sided, one-sided, fixed (l = u) and absent.
BoxProblem random_problem(int n, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  BoxProblem p;
  Eigen::MatrixXd M(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) M(i, j) = normal(rng);
  p.A = M * M.transpose() / n + 0.1 * Eigen::MatrixXd::Identity(n, n);
  p.b = Eigen::VectorXd(n);
  p.l = Eigen::VectorXd(n);
  p.u = Eigen::VectorXd(n);
  for (int i = 0; i < n; ++i) {
    p.b[i] = 2.0 * normal(rng);
    const double width = 0.2 + std::abs(normal(rng));
    p.l[i] = -width + 0.3 * normal(rng);
    p.u[i] = p.l[i] + 2 * width;
    if (i % 5 == 1) p.u[i] = inf;
    if (i % 5 == 3) p.l[i] = -inf;
    if (i % 7 == 6 && std::isfinite(p.l[i])) p.u[i] = p.l[i];
  }
  return p;
}

// The solution by enumeration: for every assignment (0 lower, 1 upper, 2 free) the free unknowns solve
// A_FF x_F = b_F - A_FB x_B; the one whose x lies in the box and whose gradient g = A x - b is >= 0 at the lower
// bounds and <= 0 at the upper ones is the minimiser.
Eigen::VectorXd enumerate_solution(const BoxProblem& p) {
  const int n = static_cast<int>(p.b.size());
  int combinations = 1;
  for (int i = 0; i < n; ++i) combinations *= 3;
  double best_violation = inf;
  Eigen::VectorXd best;
  for (int code = 0; code < combinations; ++code) {
    std::vector<int> state(n), free;
    Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
    bool possible = true;
    for (int i = 0, c = code; i < n; ++i, c /= 3) {
      state[i] = c % 3;
      if (state[i] == 2) free.push_back(i);
      else x[i] = state[i] == 0 ? p.l[i] : p.u[i];
      possible = possible && std::isfinite(state[i] == 2 ? 0.0 : x[i]);
    }
    if (!possible) continue;
    const int k = static_cast<int>(free.size());
    if (k > 0) {
      Eigen::MatrixXd Aff(k, k);
      Eigen::VectorXd rhs(k);
      const Eigen::VectorXd Ax = p.A * x;
      for (int a = 0; a < k; ++a) {
        rhs[a] = p.b[free[a]] - Ax[free[a]];
        for (int c = 0; c < k; ++c) Aff(a, c) = p.A(free[a], free[c]);
      }
      const Eigen::VectorXd xf = Aff.llt().solve(rhs);
      for (int a = 0; a < k; ++a) x[free[a]] = xf[a];
    }
    const Eigen::VectorXd g = p.A * x - p.b;
    double violation = 0;
    for (int i = 0; i < n; ++i) {
      violation = std::max({violation, p.l[i] - x[i], x[i] - p.u[i]});
      if (state[i] == 0 && p.l[i] < p.u[i]) violation = std::max(violation, -g[i]);
      if (state[i] == 1 && p.l[i] < p.u[i]) violation = std::max(violation, g[i]);
    }
    if (violation < best_violation) {
      best_violation = violation;
      best = x;
    }
  }
  EXPECT_LE(best_violation, 1e-10);
  return best;
}

linalg::MprgpResult solve(const BoxProblem& p, bool jacobi, bool with_upper, const Eigen::VectorXd& x0) {
  linalg::BoundQp qp;
  qp.apply = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    y = p.A * x;
    return false;
  };
  if (jacobi)
    qp.precondition = [&](const Eigen::VectorXd& r, Eigen::VectorXd& y) {
      y = r.cwiseQuotient(p.A.diagonal());
      return false;
    };
  qp.b = p.b;
  qp.lower = p.l;
  if (with_upper) qp.upper = p.u;
  linalg::MprgpSettings settings;
  settings.alpha_bar = 1.9 / p.A.selfadjointView<Eigen::Lower>().eigenvalues().maxCoeff();
  const double scale = p.b.norm();
  return linalg::solve_mprgp(qp, x0, settings,
                             [&](const linalg::MprgpResult& state) { return state.projected_gradient() <= 1e-13 * scale; });
}

}  // namespace

TEST(MprgpBox, SolvesRandomBoxConstrainedQpsLikeTheEnumerationOfEveryActiveSet) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const BoxProblem p = random_problem(3 + trial % 6, rng);
    const Eigen::VectorXd reference = enumerate_solution(p);
    for (bool jacobi : {false, true}) {
      // From zero (projected onto the box) and from a start outside the box on both sides.
      for (double start : {0.0, 5.0, -5.0}) {
        const auto r = solve(p, jacobi, true, Eigen::VectorXd::Constant(p.b.size(), start));
        ASSERT_TRUE(r.report.converged()) << trial;
        EXPECT_TRUE(((r.x - p.l).array() >= 0).all() && ((p.u - r.x).array() >= 0).all()) << trial;
        EXPECT_LE((r.x - reference).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, reference.cwiseAbs().maxCoeff()))
            << "trial " << trial << (jacobi ? " (Jacobi)" : "") << " start " << start;
        // The projected gradient at the answer, computed from its definition: zero to the tolerance.
        const Eigen::VectorXd g = p.A * r.x - p.b;
        EXPECT_LE(linalg::projected_gradient(r.x, g, p.l, p.u).norm(), 1e-11 * p.b.norm()) << trial;
      }
    }
  }
}

TEST(MprgpBox, LargerBoxProblemsConvergeWithTheirBoundsOnBothSidesActive) {
  // Beyond the enumeration's reach: the KKT conditions checked directly, with unknowns at both bounds.
  std::mt19937 rng(17);
  for (int n : {40, 120}) {
    const BoxProblem p = random_problem(n, rng);
    const auto r = solve(p, true, true, Eigen::VectorXd::Zero(n));
    ASSERT_TRUE(r.report.converged()) << n;
    const Eigen::VectorXd g = p.A * r.x - p.b;
    int at_lower = 0, at_upper = 0;
    for (int i = 0; i < n; ++i) {
      if (p.l[i] == p.u[i]) continue;
      if (r.x[i] == p.l[i]) {
        ++at_lower;
        EXPECT_GE(g[i], -1e-11 * p.b.norm());
      } else if (r.x[i] == p.u[i]) {
        ++at_upper;
        EXPECT_LE(g[i], 1e-11 * p.b.norm());
      } else {
        EXPECT_LE(std::abs(g[i]), 1e-11 * p.b.norm());
      }
    }
    EXPECT_GT(at_lower, 0);
    EXPECT_GT(at_upper, 0);
  }
}

TEST(MprgpBox, AnAbsentOrInfiniteUpperBoundIsTheOneSidedMethod) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 5; ++trial) {
    BoxProblem p = random_problem(30, rng);
    p.l = p.l.cwiseMax(-1.0);  // finite lower bounds
    const auto absent = solve(p, true, false, Eigen::VectorXd::Zero(30));
    p.u = Eigen::VectorXd::Constant(30, inf);
    const auto infinite = solve(p, true, true, Eigen::VectorXd::Zero(30));
    ASSERT_TRUE(absent.report.converged());
    EXPECT_EQ(absent.report.iterations, infinite.report.iterations);
    EXPECT_EQ((absent.x - infinite.x).cwiseAbs().maxCoeff(), 0.0);
    // x >= l alone: the enumeration with u = +inf (no upper assignments possible).
    if (trial < 2) {
      BoxProblem small = random_problem(7, rng);
      small.l = small.l.cwiseMax(-1.0);
      small.u = Eigen::VectorXd::Constant(7, inf);
      const Eigen::VectorXd reference = enumerate_solution(small);
      const auto r = solve(small, false, false, Eigen::VectorXd::Zero(7));
      EXPECT_LE((r.x - reference).cwiseAbs().maxCoeff(), 1e-9 * std::max(1.0, reference.cwiseAbs().maxCoeff()));
    }
  }
}

TEST(MprgpBox, CarriesTheImageOfItsIterateUnderTheCallersLinearMap) {
  // The problem's `image` hands over L v of every vector `apply` took; MPRGP must then carry L x through its CG,
  // expansion and proportioning steps. Checked against L x itself at every stopping test, on problems whose
  // answers sit on both bounds (so every kind of step is taken), and the iterates must be those without it.
  std::mt19937 rng(29);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int n : {12, 60}) {
    const BoxProblem p = random_problem(n, rng);
    Eigen::MatrixXd L(3, n);
    for (Eigen::Index i = 0; i < L.size(); ++i) L.data()[i] = normal(rng);
    Eigen::VectorXd last;
    linalg::BoundQp qp;
    qp.apply = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) {
      y = p.A * x;
      last = L * x;
      return false;
    };
    qp.image = [&]() -> const Eigen::VectorXd& { return last; };
    qp.b = p.b;
    qp.lower = p.l;
    qp.upper = p.u;
    linalg::MprgpSettings settings;
    settings.alpha_bar = 1.9 / p.A.selfadjointView<Eigen::Lower>().eigenvalues().maxCoeff();
    const double scale = p.b.norm();
    double worst = 0.0;
    int tests = 0;
    const auto r = linalg::solve_mprgp(qp, Eigen::VectorXd::Zero(n), settings, [&](const linalg::MprgpResult& s) {
      const Eigen::VectorXd exact = L * s.x;
      worst = std::max(worst, (s.image - exact).norm() / std::max(1.0, L.norm() * s.x.norm()));
      ++tests;
      return s.projected_gradient() <= 1e-13 * scale;
    });
    ASSERT_TRUE(r.report.converged()) << n;
    EXPECT_GT(r.cg_steps, 0);
    EXPECT_GT(r.expansion_steps + r.proportioning_steps, 0) << n;
    EXPECT_EQ(tests, r.cg_steps + r.expansion_steps + r.proportioning_steps + 1);
    EXPECT_LE(worst, 1e-12) << n;
    const auto plain = solve(p, false, true, Eigen::VectorXd::Zero(n));
    EXPECT_EQ(plain.report.iterations, r.report.iterations) << n;
    EXPECT_EQ((plain.x - r.x).cwiseAbs().maxCoeff(), 0.0) << n;
  }
}
