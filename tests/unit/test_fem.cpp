// FEM layer: Q1 element properties and patch tests (linear fields reproduced exactly on distorted meshes).
#include "fem/body_solver.hpp"
#include "fem/elasticity.hpp"
#include "element_checks.hpp"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <random>

using namespace contact;
using namespace contact::fem;

namespace {

Model strain_model() { return Model{}; }

// A 6x5 block of [0,3]x[0,2] whose interior nodes are moved at random by up to 30 % of the spacing.
mesh::Mesh distorted_block() {
  mesh::BlockSpec s;
  s.corners = {mesh::Point(0, 0), mesh::Point(3, 0), mesh::Point(3, 2), mesh::Point(0, 2)};
  s.nx = 6;
  s.ny = 5;
  mesh::Mesh m = mesh::make_block(s);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> shift(-0.15, 0.15);
  const auto lo = m.bbox_min(), hi = m.bbox_max();
  for (auto& p : m.nodes) {
    const bool boundary = p.x() <= lo.x() || p.x() >= hi.x() || p.y() <= lo.y() || p.y() >= hi.y();
    if (!boundary) p += Eigen::Vector2d(shift(rng), shift(rng) * 0.8);
  }
  return m;
}

// The linear field of the patch tests: u = a + G x.
Eigen::Vector2d linear_field(const Eigen::Vector2d& x) {
  Eigen::Matrix2d G;
  G << 1.0e-3, 4.0e-4, -2.0e-4, -6.0e-4;
  return Eigen::Vector2d(2e-3, -1e-3) + G * x;
}

}  // namespace

TEST(Q1Element, StiffnessIsSymmetricWithExactlyThreeRigidModesInItsNullSpace) {
  Eigen::Matrix<double, 4, 2> x;
  x << 0.1, 0.0, 1.3, 0.2, 1.1, 0.9, -0.1, 1.2;  // a general convex quadrilateral
  for (Plane plane : {Plane::strain, Plane::stress}) {
    const Elasticity el = make_elasticity({2.1e5, 0.3}, Model{plane, 0.5});
    contact::testing::expect_symmetric_with_rigid_null_space<4>(element_stiffness(x, el), x);
  }
}

TEST(PatchTest, LinearDisplacementIsReproducedExactlyOnADistortedMesh) {
  // With the linear field u* prescribed on the boundary, the FE solution equals u* everywhere iff u*
  // satisfies the interior equations, (K u*)_i = 0 for every interior dof i (the solution is unique).
  // The field includes shear and rotation; the mesh is distorted, so this is the real patch test.
  Body body;
  body.name = "patch";
  body.material = {2.1e5, 0.3};
  body.mesh = distorted_block();
  ASSERT_TRUE(mesh::check_cells(body.mesh).empty());
  BoundaryCondition left{"left", BoundaryCondition::Kind::displacement};
  left.ux = 0.0;
  left.uy = 0.0;
  body.boundary = {left};
  BodySolver solver(body, strain_model());
  ASSERT_TRUE(solver.ok()) << solver.error();
  Eigen::VectorXd ustar(2 * body.mesh.num_nodes());
  for (int n = 0; n < body.mesh.num_nodes(); ++n)
    ustar.segment<2>(2 * n) = linear_field(body.mesh.nodes[static_cast<size_t>(n)]);
  const Eigen::VectorXd r = solver.stiffness() * ustar;
  const double scale = (solver.stiffness().cwiseAbs() * ustar.cwiseAbs()).maxCoeff();
  int interior = 0;
  for (int n = 0; n < body.mesh.num_nodes(); ++n) {
    const auto& p = body.mesh.nodes[static_cast<size_t>(n)];
    if (p.x() <= 0 || p.x() >= 3 || p.y() <= 0 || p.y() >= 2) continue;
    ++interior;
    EXPECT_LE(r.segment<2>(2 * n).norm(), 1e-12 * scale) << "node " << n;
  }
  EXPECT_EQ(interior, 5 * 4);
  // The stresses of a linear field are constant, and equal to D applied to its strain.
  const auto s = solver.stresses(ustar);
  const Eigen::Vector3d strain(1.0e-3, -6.0e-4, 4.0e-4 - 2.0e-4);
  const Eigen::Vector3d exact = solver.elasticity().D * strain;
  for (int c = 0; c < body.mesh.num_cells(); ++c) EXPECT_LE((s.cell.row(c).head<3>().transpose() - exact).norm(), 1e-9 * exact.norm());
  for (int n = 0; n < body.mesh.num_nodes(); ++n) EXPECT_LE((s.node.row(n).head<3>().transpose() - exact).norm(), 1e-9 * exact.norm());
}

TEST(PatchTest, TractionLoadedPatchGivesUniformStressOnADistortedMesh) {
  // Uniform stress sxx = 30, syy = -50 (plane strain), shear-free: compatible with the symmetry supports on the
  // left and bottom; the right and top carry the exact tractions (element_checks.hpp).
  contact::testing::expect_uniform_traction_state(contact::testing::uniform_traction_body(distorted_block(), false));
}

TEST(Constraints, ChainsResolveAndTheMapIsExactOnFreeAndConstrainedDofs) {
  Constraints c(5);
  c.add_dirichlet(0, 2.0);
  c.add_line(3, {{1, 0.5}, {4, 0.5}});        // a hanging-node style average
  c.add_line(4, {{0, 1.0}, {2, 1.0}}, 0.25);   // a chain: 4 depends on a prescribed and a free dof
  ASSERT_EQ(c.close(), "");
  EXPECT_EQ(c.n_free(), 2);  // dofs 1 and 2
  Eigen::VectorXd x(2);
  x << 10, 20;
  const Eigen::VectorXd u = c.expand(x);
  EXPECT_DOUBLE_EQ(u[0], 2.0);
  EXPECT_DOUBLE_EQ(u[1], 10.0);
  EXPECT_DOUBLE_EQ(u[2], 20.0);
  EXPECT_DOUBLE_EQ(u[4], 2.0 + 20.0 + 0.25);
  EXPECT_DOUBLE_EQ(u[3], 0.5 * 10.0 + 0.5 * u[4]);
  Constraints cyc(2);
  cyc.add_line(0, {{1, 1.0}});
  cyc.add_line(1, {{0, 1.0}});
  EXPECT_NE(cyc.close().find("cycle"), std::string::npos);
}

TEST(BodySolver, AnUnrestrainedBodyIsReportedNotCrashed) {
  Body body;
  body.name = "floating";
  body.material = {1.0, 0.3};
  mesh::BlockSpec s;
  s.corners = {mesh::Point(0, 0), mesh::Point(1, 0), mesh::Point(1, 1), mesh::Point(0, 1)};
  s.nx = s.ny = 2;
  body.mesh = mesh::make_block(s);
  BoundaryCondition left{"left", BoundaryCondition::Kind::displacement};
  left.ux = 0.0;  // y translation still free
  body.boundary = {left};
  BodySolver solver(body, strain_model());
  EXPECT_FALSE(solver.ok());
  EXPECT_NE(solver.error().find("floating"), std::string::npos);
}
