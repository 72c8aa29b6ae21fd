// The primal-dual active set on the interface (solver/linalg/active_set.cpp) as pure linear algebra: on random
// symmetric positive definite problems its answer satisfies the complementarity conditions and equals the
// independent active-set QP method; the nested coarse guess is non-negative and saves steps.
#include "linalg/active_set.hpp"

#include <Eigen/LU>
#include <gtest/gtest.h>

#include <random>

using namespace contact::linalg;

namespace {

// A compliance-like SPD matrix: the Green's function of a 1-D elastic line (dense, positive entries).
Eigen::MatrixXd compliance(int n) {
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    K(i, i) = 2.0 + 0.01;
    if (i > 0) K(i, i - 1) = K(i - 1, i) = -1.0;
  }
  return K.inverse();
}

bool always(const Eigen::VectorXd&, const Eigen::VectorXd&, const ActiveSetStep&) { return false; }  // never stops

}  // namespace

TEST(ActiveSet, SolutionSatisfiesComplementarityAndEqualsTheQpMethod) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 5 + trial * 3;
    Eigen::MatrixXd A(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) A(i, j) = normal(rng);
    const Eigen::MatrixXd H = A * A.transpose() + n * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd g(n);
    for (int i = 0; i < n; ++i) g[i] = normal(rng);
    const QpSolution r = solve_active_set(H.sparseView(), g, 100, always);
    ASSERT_TRUE(r.report.converged()) << r.report.message;
    const Eigen::VectorXd h = g + H * r.z;
    const double scale = g.cwiseAbs().maxCoeff();
    for (int i = 0; i < n; ++i) {
      EXPECT_GE(r.z[i], 0.0);
      EXPECT_GE(h[i], -1e-12 * scale);
      EXPECT_NEAR(r.z[i] * h[i], 0.0, 1e-12 * scale * std::max(1.0, r.z.cwiseAbs().maxCoeff()));
    }
    const Eigen::VectorXd qp = solve_nonnegative_qp(H.sparseView(), g);
    EXPECT_LE((qp - r.z).cwiseAbs().maxCoeff(), 1e-10 * std::max(1.0, r.z.cwiseAbs().maxCoeff())) << trial;
  }
}

TEST(ActiveSet, NestedGuessIsNonNegativeAndLeavesAHandfulOfFineStepsAtEverySize) {
  // A contact zone shrinking from a first guess that overestimates it: g = -(1 - (x / 0.8)^2) on a line of n
  // nodes (penetration where |x| < 0.8) pushed back by a softening compliance.
  for (int n : {65, 257, 1025}) {
    const SparseMatrix H = (compliance(n) / n).sparseView();
    Eigen::VectorXd g(n), position(n);
    for (int i = 0; i < n; ++i) {
      const double x = -1.0 + 2.0 * i / (n - 1);
      position[i] = x;
      g[i] = -(1.0 - x * x / 0.64) / n;
    }
    const std::vector<int> line(static_cast<size_t>(n), 0);
    const QpSolution plain = solve_active_set(H, g, 100, always);
    std::vector<std::pair<Eigen::Index, int>> levels;
    const Eigen::VectorXd z0 = nested_initial_guess(H, g, line, position, {}, &levels);
    EXPECT_GE(z0.minCoeff(), 0.0);
    EXPECT_FALSE(levels.empty());
    const QpSolution nested = solve_active_set(H, g, 100, always, &z0);
    ASSERT_TRUE(plain.report.converged() && nested.report.converged());
    EXPECT_LE((nested.z - plain.z).cwiseAbs().maxCoeff(), 1e-10 * plain.z.cwiseAbs().maxCoeff());
    EXPECT_LE(nested.report.iterations, 3) << n << " nodes (without the guess: " << plain.report.iterations << ")";
    EXPECT_GT(plain.report.iterations, 2 * nested.report.iterations) << n;  // the edge moving a few nodes per step from the plain guess
    for (const auto& [size, steps] : levels) EXPECT_LE(steps, 4) << size;
  }
}
