// Anderson mixing of a fixed point on x >= 0 (linalg/anderson.hpp, NonnegativeAnderson): the mixing that the
// augmented-Lagrangian multipliers and the iterative solver's Coulomb slip bounds share.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "../solver/linalg/anderson.hpp"

namespace {

using contact::linalg::NonnegativeAnderson;

// g(x) = max(0, M x + c) with M symmetric, eigenvalues in [0.5, 0.95]: a contraction whose plain iteration gains a
// factor 0.95 per step.
struct Map {
  Eigen::MatrixXd M;
  Eigen::VectorXd c;
  Eigen::VectorXd operator()(const Eigen::VectorXd& x) const { return (M * x + c).cwiseMax(0.0); }
};

Map make_map(int n, unsigned seed) {
  std::srand(seed);
  const Eigen::MatrixXd A = Eigen::MatrixXd::Random(n, n);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A + A.transpose());
  Eigen::VectorXd values(n);
  for (int i = 0; i < n; ++i) values[i] = 0.5 + 0.45 * i / (n - 1);  // in [0.5, 0.95]
  Map g;
  g.M = eig.eigenvectors() * values.asDiagonal() * eig.eigenvectors().transpose();
  g.c = Eigen::VectorXd::Random(n) + Eigen::VectorXd::Constant(n, 1.0);
  g.c.head(3).setConstant(-20.0);  // a few components the cut holds at 0
  return g;
}

// Iterations until |g(x) - x| <= 1e-10 |g(x)|, plain or mixed (at most `limit`); x is the last iterate.
int iterate(const Map& g, bool mix, int limit, Eigen::VectorXd& x) {
  NonnegativeAnderson mixing(5);
  x = Eigen::VectorXd::Zero(g.c.size());
  for (int k = 1; k <= limit; ++k) {
    const Eigen::VectorXd image = g(x);
    if ((image - x).norm() <= 1e-10 * image.norm()) return k;
    x = mix ? mixing.next(image, image - x) : image;
  }
  return limit + 1;
}

TEST(NonnegativeAnderson, ReachesTheFixedPointOfAContractionInFarFewerStepsThanThePlainIteration) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Map g = make_map(40, seed);
    Eigen::VectorXd plain, mixed;
    const int k_plain = iterate(g, false, 2000, plain);
    const int k_mixed = iterate(g, true, 2000, mixed);
    ASSERT_LE(k_plain, 2000) << seed;
    ASSERT_LE(k_mixed, 2000) << seed;
    // The plain iteration gains 0.95 per step in the slowest direction (hundreds of steps to 1e-10); the mixing
    // (depth 5) is a Krylov method on the affine pieces: a fraction of that.
    EXPECT_GT(k_plain, 150) << seed;
    EXPECT_LT(k_mixed, k_plain / 3) << seed << ": " << k_mixed << " vs " << k_plain;
    // The same fixed point, on x >= 0, with some components held at 0 by the cut.
    EXPECT_LT((mixed - plain).norm(), 1e-8 * plain.norm()) << seed;
    EXPECT_GE(mixed.minCoeff(), 0.0);
    EXPECT_LT((g(mixed) - mixed).norm(), 1e-9 * mixed.norm()) << seed;
    EXPECT_LT((g.M * plain + g.c).minCoeff(), 0.0) << seed << ": no component cut, the projection untested";
  }
}

TEST(NonnegativeAnderson, ReturnsTheImageUntilItHasAHistoryAndAfterAReset) {
  NonnegativeAnderson mixing(5);
  const Eigen::VectorXd image = Eigen::VectorXd::LinSpaced(4, -1.0, 2.0);
  EXPECT_EQ(mixing.next(image, Eigen::VectorXd::Ones(4)), image.cwiseMax(0.0));
  EXPECT_FALSE(mixing.mixed());
  mixing.next(image * 0.5, Eigen::VectorXd::Ones(4) * 0.5);
  EXPECT_TRUE(mixing.mixed());
  mixing.reset();
  EXPECT_EQ(mixing.next(image, Eigen::VectorXd::Ones(4)), image.cwiseMax(0.0));
  EXPECT_FALSE(mixing.mixed());
}

}  // namespace
