// The friction Newton (solver/linalg/friction_newton.cpp) as pure linear algebra, on random problems with coupled
// normal and tangential compliance: its answer satisfies the Coulomb conditions, equals the Tresca QP's minimiser
// found by an independent method (accelerated projected gradient), and it converges from starts where the
// full-step iteration cycles.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "linalg/friction_nested.hpp"
#include "linalg/friction_newton.hpp"

using namespace contact::linalg;

namespace {

// A random frictional problem of `nodes` contact nodes: lambda = [z; q], a compliance F = A A^T / n + I coupling
// every unknown, gaps that penetrate at about half the nodes, slips of either sign.
struct Problem {
  int nodes = 0;
  SparseMatrix F;
  Eigen::VectorXd g;
  std::vector<FrictionRow> rows;
  std::vector<char> mask;
  Eigen::VectorXd c;
};

Problem random_problem(unsigned seed, int nodes, bool coulomb, double mu_or_bound, double coupling = 1.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const int n = 2 * nodes;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = normal(rng);
  Eigen::MatrixXd F = coupling * A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n);
  Problem p;
  p.nodes = nodes;
  p.F = F.sparseView();
  p.g.resize(n);
  for (int i = 0; i < n; ++i) p.g[i] = normal(rng) - (i < nodes ? 0.3 : 0.0);
  for (int i = 0; i < nodes; ++i)
    p.rows.push_back({i, nodes + i, coulomb, coulomb ? mu_or_bound : 0.0, coulomb ? 0.0 : mu_or_bound});
  p.mask = tangential_mask(n, p.rows);
  p.c = friction_scaling(p.F);
  return p;
}

// The cycling search's problems: 2 to 6 nodes, the compliance's coupling between 1 and 51, mu up to 0.7 (1.7 for
// seeds 132 and 177), all drawn from the seed.
Problem random_cycling_problem(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> count(2, 6);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const int nodes = count(rng), n = 2 * nodes;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = normal(rng);
  const double coupling = 1 + 50 * uniform(rng);
  const double mu = seed < 1000 ? 0.2 + 1.5 * uniform(rng) : 0.1 + 0.6 * uniform(rng);
  Problem p;
  p.nodes = nodes;
  p.F = Eigen::MatrixXd(coupling * A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n)).sparseView();
  p.g.resize(n);
  for (int i = 0; i < n; ++i) p.g[i] = normal(rng) - (i < nodes ? 0.3 : 0.0);
  for (int i = 0; i < nodes; ++i) p.rows.push_back({i, nodes + i, true, mu, 0.0});
  p.mask = tangential_mask(n, p.rows);
  p.c = friction_scaling(p.F);
  return p;
}

FrictionNewtonProblem newton_problem(const Problem& p) {
  return {p.rows, p.mask, p.c, [&p](const FrictionParametrization& par, FrictionIterate& x) {
            return solve_on_friction_sets(p.F, p.g, Equalities{}, par, x);
          }};
}

// Every node pressing and sticking: the start far from the answer.
FrictionSets all_sticking(const Problem& p) {
  FrictionSets s;
  s.active.assign(p.mask.size(), 0);
  for (int i = 0; i < p.nodes; ++i) s.active[static_cast<size_t>(i)] = 1;
  stick_where_in_contact(s, p.rows);
  return s;
}

// The full-step iteration the globalisation replaces: predict, solve, until the sets repeat.
bool full_steps_settle(const Problem& p, FrictionSets sets, int max_steps) {
  for (int k = 0; k < max_steps; ++k) {
    FrictionIterate x;
    if (!solve_on_friction_sets(p.F, p.g, Equalities{}, parametrize(sets, p.rows, p.mask), x)) return false;
    const FrictionSets next = predict_friction_sets(x.lambda, x.h, p.c, p.rows, p.mask);
    if (next == sets) return true;
    sets = next;
  }
  return false;
}

// Coulomb's conditions at x, to `tol` relative to the data.
void expect_coulomb_conditions(const Problem& p, const FrictionIterate& x, double tol) {
  const double scale = std::max(1.0, x.lambda.cwiseAbs().maxCoeff()) * std::max(1.0, p.g.cwiseAbs().maxCoeff());
  for (const auto& r : p.rows) {
    const double z = x.lambda[r.normal], hn = x.h[r.normal], q = x.lambda[r.tangential], w = x.h[r.tangential];
    const double b = r.coulomb ? r.mu * z : r.bound;
    EXPECT_GE(z, -tol * scale);
    EXPECT_GE(hn, -tol * scale);
    EXPECT_NEAR(z * hn, 0.0, tol * scale);
    EXPECT_LE(std::abs(q), b + tol * scale);
    if (std::abs(q) < b - tol * scale) EXPECT_NEAR(w, 0.0, tol * scale);  // sticks
    EXPECT_LE(q * w, tol * scale);                                        // slips against its traction
  }
}

// The Tresca problem's minimiser, min 1/2 l^T F l + g^T l over z >= 0, |q| <= bound, by accelerated projected
// gradient (FISTA with restarts): independent of the active sets.
Eigen::VectorXd tresca_minimiser(const Problem& p, double bound) {
  const Eigen::MatrixXd F = Eigen::MatrixXd(p.F);
  const double L = F.operatorNorm() * 1.01;
  const int n = static_cast<int>(p.g.size());
  auto project = [&](Eigen::VectorXd v) {
    for (int i = 0; i < n; ++i) v[i] = i < p.nodes ? std::max(0.0, v[i]) : std::clamp(v[i], -bound, bound);
    return v;
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n), y = x;
  double t = 1.0;
  for (int k = 0; k < 200000; ++k) {
    const Eigen::VectorXd next = project(y - (F * y + p.g) / L);
    const double t_next = (1 + std::sqrt(1 + 4 * t * t)) / 2;
    if ((next - x).dot(y - next) > 0) {  // restart where the momentum points uphill
      y = next;
      t = 1.0;
    } else {
      y = next + ((t - 1) / t_next) * (next - x);
      t = t_next;
    }
    if ((next - x).norm() <= 1e-15 * std::max(1.0, next.norm())) return next;
    x = next;
  }
  return x;
}

}  // namespace

TEST(FrictionNewton, CoulombAnswerSatisfiesTheConditionsFromEveryStart) {
  for (unsigned seed = 0; seed < 40; ++seed) {
    const Problem p = random_problem(seed, 12, true, 0.2 + 0.05 * (seed % 10));
    FrictionNewtonSettings settings;
    settings.max_steps = 200;
    const FrictionNewtonResult r = friction_newton(newton_problem(p), all_sticking(p), settings);
    ASSERT_EQ(r.report.stop, contact::SolveStop::converged) << "seed " << seed << " after " << r.report.iterations << " steps";
    expect_coulomb_conditions(p, r.iterate, 1e-10);
  }
}

TEST(FrictionNewton, TrescaAnswerIsTheMinimiserOfItsConvexProblem) {
  for (unsigned seed = 0; seed < 10; ++seed) {
    const double bound = 0.1 + 0.05 * seed;
    const Problem p = random_problem(100 + seed, 8, false, bound);
    const FrictionNewtonResult r = friction_newton(newton_problem(p), all_sticking(p), FrictionNewtonSettings{});
    ASSERT_EQ(r.report.stop, contact::SolveStop::converged) << seed;
    const Eigen::VectorXd reference = tresca_minimiser(p, bound);
    EXPECT_LE((r.iterate.lambda - reference).cwiseAbs().maxCoeff(),
              1e-9 * std::max(1.0, reference.cwiseAbs().maxCoeff()))
        << seed;
  }
}

TEST(FrictionNewton, ConvergesWhereTheFullStepsCycle) {
  // Problems of 2 to 6 nodes with a strongly coupled compliance, drawn as in random_cycling_problem, on which the
  // full-step iteration from "everything sticks" never settles (its sets cycle; found by searching 20,000 seeds,
  // where it happens for about one in 3,000 with mu <= 0.7): the globalised iteration settles on each, at a
  // point that satisfies Coulomb's conditions.
  for (unsigned seed : {132u, 177u, 14056u, 16582u, 16740u}) {
    const Problem p = random_cycling_problem(seed);
    EXPECT_FALSE(full_steps_settle(p, all_sticking(p), 100)) << seed;
    FrictionNewtonSettings settings;
    settings.max_steps = 400;
    const FrictionNewtonResult r = friction_newton(newton_problem(p), all_sticking(p), settings);
    ASSERT_EQ(r.report.stop, contact::SolveStop::converged) << "seed " << seed << " after " << r.report.iterations << " steps";
    EXPECT_GT(r.damped_steps, 0) << seed;
    expect_coulomb_conditions(p, r.iterate, 1e-9);
  }
}

TEST(FrictionSetsSystem, AConsistentSingularSystemIsSolvedWithTheLeastRigidMotionAnInconsistentOneIsRefused) {
  // Two floating bodies, one rigid mode each (rows of G), three multipliers: the first is free (the sets' unknown),
  // the other two act on body 2 only and are prescribed by the sets (slip at a Tresca bound: lambda0). Body 2's row
  // of G P is zero, so the sets' system is singular: body 2's motion is fixed by no free multiplier. If the loads on
  // body 2 (e_2) balance the prescribed tractions (G_2 lambda0 = e_2: a brick whose joints slip at the same force
  // above and below) every motion is an equilibrium and the answer is the one without it (alpha_2 = 0); if they do
  // not, no equilibrium exists and the solve says so.
  Eigen::MatrixXd Fd(3, 3);
  Fd << 2.0, 0.3, 0.1, 0.3, 1.5, 0.2, 0.1, 0.2, 1.0;
  const SparseMatrix F = Fd.sparseView();
  const Eigen::VectorXd g = Eigen::Vector3d(-0.4, 0.1, 0.2);
  Eigen::MatrixXd Gd(2, 3);
  Gd << 1.0, 0.0, 0.0, 0.0, 1.0, -1.0;
  FrictionParametrization p;
  p.rows = {0};
  p.P = SparseMatrix(3, 1);
  p.P.insert(0, 0) = 1.0;
  p.lambda0 = Eigen::Vector3d(0.0, 0.7, 0.7);  // the two prescribed tractions cancel on body 2
  for (const double load : {0.0, 0.05}) {
    Equalities eq;
    eq.G = Gd.sparseView();
    eq.e = Eigen::Vector2d(0.5, load);
    FrictionIterate x;
    const bool solved = solve_on_friction_sets(F, g, eq, p, x);
    if (load != 0.0) {
      EXPECT_FALSE(solved) << "body 2's load is not balanced: no equilibrium";
      continue;
    }
    ASSERT_TRUE(solved);
    // Both bodies in equilibrium, to the regularisation's 1e-10 (the solve accepts at most 1e-9 relative).
    EXPECT_NEAR((eq.G * x.lambda - eq.e).norm(), 0.0, 1e-9 * eq.e.norm());
    EXPECT_NEAR(x.lambda[0], 0.5, 1e-9);  // body 1's: G_1 lambda = lambda_0 = e_1
    EXPECT_NEAR(x.h[0], 0.0, 1e-10);                           // the free row's gap closed
    EXPECT_NEAR(std::abs(x.other[1]), 0.0, 1e-8);               // body 2 not moved
  }
}
