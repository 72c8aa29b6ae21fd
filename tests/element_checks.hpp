// Checks shared by the element tests (Q1 in test_fem.cpp, P1 in test_triangles.cpp).
#pragma once

#include "fem/body_solver.hpp"
#include "contact/problem.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <utility>

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

// The uniform state sxx = 30, syy = -50, sxy = 0 of the traction patch test on `mesh`, a body [0, 3] x [0, 2]
// with the block's edge names (E = 2.1e5, nu = 0.3): symmetry supports on the left (u_x = 0) and the bottom
// (u_y = 0), the exact tractions t = sigma n on the right and the top (the top's as a normal pressure when
// `top_as_pressure`). The boundary is [left, bottom, right, top].
constexpr double kPatchSxx = 30, kPatchSyy = -50;
inline Body uniform_traction_body(mesh::Mesh mesh, bool top_as_pressure) {
  Body body;
  body.name = "patch";
  body.material = {2.1e5, 0.3};
  body.mesh = std::move(mesh);
  BoundaryCondition left{"left", BoundaryCondition::Kind::displacement};
  left.ux = 0.0;
  BoundaryCondition bottom{"bottom", BoundaryCondition::Kind::displacement};
  bottom.uy = 0.0;
  BoundaryCondition right{"right", BoundaryCondition::Kind::traction};
  right.traction = Eigen::Vector2d(kPatchSxx, 0);
  BoundaryCondition top{"top", BoundaryCondition::Kind::traction};
  if (top_as_pressure) {
    top.normal_pressure = true;
    top.pressure = -kPatchSyy;
  } else {
    top.traction = Eigen::Vector2d(0, kPatchSyy);
  }
  body.boundary = {left, bottom, right, top};
  return body;
}

// Its FE solution (plane strain) is that state exactly: every cell's stresses (szz = nu (sxx + syy)), every node's
// recovered syy, and reactions that balance the tractions (sum -sxx * 2 in x, -syy * 3 in y).
inline void expect_uniform_traction_state(const Body& body) {
  const double sxx = kPatchSxx, syy = kPatchSyy;
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << solver.error();
  const Eigen::VectorXd u = solver.solve(Eigen::VectorXd());
  const auto s = solver.stresses(u);
  for (int c = 0; c < body.mesh.num_cells(); ++c) {
    EXPECT_NEAR(s.cell(c, 0), sxx, 1e-8 * 50) << "cell " << c;
    EXPECT_NEAR(s.cell(c, 1), syy, 1e-8 * 50) << "cell " << c;
    EXPECT_NEAR(s.cell(c, 2), 0.0, 1e-8 * 50) << "cell " << c;
    EXPECT_NEAR(s.cell(c, 3), 0.3 * (sxx + syy), 1e-8 * 50) << "cell " << c;
  }
  for (int n = 0; n < body.mesh.num_nodes(); ++n) EXPECT_NEAR(s.node(n, 1), syy, 1e-7 * 50) << "node " << n;
  const Eigen::VectorXd R = solver.reactions(u, Eigen::VectorXd());
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (int n = 0; n < body.mesh.num_nodes(); ++n) total += R.segment<2>(2 * n);
  EXPECT_NEAR(total.x(), -sxx * 2.0, 1e-9 * 150);
  EXPECT_NEAR(total.y(), -syy * 3.0, 1e-9 * 150);
}

}  // namespace contact::testing
