// Checks shared by the element tests (Q1 in test_fem.cpp, P1 in test_triangles.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>

namespace contact::testing {

// An element stiffness K of the corners x (rows = local nodes) is symmetric, positive semi-definite, has exactly
// three zero eigenvalues, and they are the rigid motions: two translations and the infinitesimal rotation.
template <int N>
void expect_symmetric_with_rigid_null_space(const Eigen::Matrix<double, 2 * N, 2 * N>& K,
                                            const Eigen::Matrix<double, N, 2>& x) {
  EXPECT_LE((K - K.transpose()).cwiseAbs().maxCoeff(), 1e-12 * K.cwiseAbs().maxCoeff());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 2 * N, 2 * N>> eig(K);
  const auto& ev = eig.eigenvalues();
  const double largest = ev.maxCoeff();
  int zero = 0;
  for (int i = 0; i < 2 * N; ++i) {
    EXPECT_GT(ev[i], -1e-10 * largest);
    if (std::abs(ev[i]) < 1e-10 * largest) ++zero;
  }
  EXPECT_EQ(zero, 3);
  Eigen::Matrix<double, 2 * N, 3> rigid;
  for (int k = 0; k < N; ++k) {
    rigid.row(2 * k) << 1, 0, -x(k, 1);
    rigid.row(2 * k + 1) << 0, 1, x(k, 0);
  }
  EXPECT_LE((K * rigid).cwiseAbs().maxCoeff(), 1e-10 * largest);
}

}  // namespace contact::testing
