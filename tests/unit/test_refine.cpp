// Refinement with hanging nodes: 1-irregularity, curved boundaries, constraints, patch test and convergence.
#include "fem/body_solver.hpp"
#include "lame_ring.hpp"
#include "contact/mesh.hpp"
#include "refine_checks.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

using namespace contact;
using contact::testing::max_nodes_inside_a_side;
using contact::testing::refine_towards;

namespace {

mesh::Mesh square(int n) {
  mesh::BlockSpec s;
  s.corners = {mesh::Point(0, 0), mesh::Point(2, 0), mesh::Point(2, 2), mesh::Point(0, 2)};
  s.nx = s.ny = n;
  return mesh::make_block(s);
}

// A steel body on square(3), to be refined by the test.
Body square_body(const std::string& name) {
  Body body;
  body.name = name;
  body.material = {2.1e5, 0.3};
  body.mesh = square(3);
  return body;
}

}  // namespace

TEST(Refinement, SplitsIntoFourAndKeepsAreaAndEdgeSetsOrdered) {
  mesh::Mesh m = square(2);
  const auto r = mesh::refine(m, {0});
  EXPECT_EQ(r.refined_cells, 1);
  EXPECT_EQ(m.num_cells(), 4 + 3);
  double area = 0;
  for (int c = 0; c < m.num_cells(); ++c) area += m.cell_area(c);
  EXPECT_NEAR(area, 4.0, 1e-14);
  EXPECT_TRUE(mesh::check_cells(m).empty());
  const auto bottom = m.edge_set_nodes("bottom");
  ASSERT_EQ(bottom.size(), 4u);  // 0, 0.5, 1, 2
  for (size_t k = 0; k + 1 < bottom.size(); ++k) EXPECT_LT(m.nodes[bottom[k]].x(), m.nodes[bottom[k + 1]].x());
  // The refined cell's two interior sides now carry hanging nodes on its unrefined neighbours.
  EXPECT_EQ(mesh::hanging_nodes(m).size(), 2u);
}

TEST(Refinement, LocalRefinementStaysOneIrregular) {
  mesh::Mesh m = square(2);
  // Five levels towards a point near (not at) a corner: the closure must refine coarser neighbours.
  EXPECT_GT(refine_towards(m, mesh::Point(0.3, 0.01), 5), 0);
  EXPECT_LE(max_nodes_inside_a_side(m), 1);
  int max_level = 0;
  for (int l : m.level) max_level = std::max(max_level, l);
  EXPECT_EQ(max_level, 5);
  EXPECT_TRUE(mesh::check_cells(m).empty());
  double area = 0;
  for (int c = 0; c < m.num_cells(); ++c) area += m.cell_area(c);
  EXPECT_NEAR(area, 4.0, 1e-12);
}

TEST(Refinement, NewBoundaryNodesLieOnTheTrueCurve) {
  mesh::BlockSpec s;
  s.corners = {mesh::Point(1, 0), mesh::Point(2, 0), mesh::Point(0, 2), mesh::Point(0, 1)};
  s.nx = 2;
  s.ny = 3;
  mesh::Curve outer, inner;
  outer.kind = inner.kind = mesh::Curve::Kind::arc;
  outer.radius = 2;
  inner.radius = 1;
  ASSERT_FALSE(mesh::fit_curve(outer, s.corners[1], s.corners[2]).has_value());
  ASSERT_FALSE(mesh::fit_curve(inner, s.corners[0], s.corners[3]).has_value());
  s.curves["right"] = outer;
  s.curves["left"] = inner;
  mesh::Mesh m = mesh::make_block(s);
  mesh::refine_uniform(m);
  mesh::refine_uniform(m);
  for (int n : m.edge_set_nodes("right")) EXPECT_NEAR(m.nodes[static_cast<size_t>(n)].norm(), 2.0, 1e-13);
  for (int n : m.edge_set_nodes("left")) EXPECT_NEAR(m.nodes[static_cast<size_t>(n)].norm(), 1.0, 1e-13);
  EXPECT_EQ(m.edge_set_nodes("right").size(), 3u * 4 + 1);
}

TEST(Refinement, TransferReproducesABilinearFieldAtTheNewNodes) {
  mesh::Mesh m = square(3);
  auto field = [](const mesh::Point& x) { return 1.0 + 2.0 * x.x() - 0.5 * x.y() + 0.25 * x.x() * x.y(); };
  Eigen::MatrixXd u(m.num_nodes(), 1);
  for (int n = 0; n < m.num_nodes(); ++n) u(n, 0) = field(m.nodes[static_cast<size_t>(n)]);
  const auto r = mesh::refine(m, {0, 4, 8});
  const Eigen::MatrixXd v = mesh::transfer(u, r, m.num_nodes());
  for (int n = 0; n < m.num_nodes(); ++n) EXPECT_NEAR(v(n, 0), field(m.nodes[static_cast<size_t>(n)]), 1e-13);
}

TEST(HangingNodes, PatchTestLinearFieldIsExactOnANonConformingMesh) {
  // Several levels of local refinement: many hanging nodes. With the exact linear field u* (which satisfies
  // every hanging-node constraint), the constrained equations at the free interior unknowns hold exactly:
  // T^T K u* = 0 there, so the FE solution with u*'s boundary values is u*.
  Body body = square_body("patch");
  refine_towards(body.mesh, mesh::Point(0.7, 1.3), 3);
  refine_towards(body.mesh, mesh::Point(1.6, 0.4), 2);
  const auto hanging = mesh::hanging_nodes(body.mesh);
  ASSERT_GE(hanging.size(), 6u);
  BoundaryCondition fix{"left", BoundaryCondition::Kind::displacement};
  fix.ux = 0.0;
  fix.uy = 0.0;
  body.boundary = {fix};
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << solver.error();
  Eigen::VectorXd ustar(2 * body.mesh.num_nodes());
  for (int n = 0; n < body.mesh.num_nodes(); ++n) {
    const auto& x = body.mesh.nodes[static_cast<size_t>(n)];
    ustar.segment<2>(2 * n) = Eigen::Vector2d(1e-3 * x.x() + 4e-4 * x.y(), -2e-4 * x.x() - 6e-4 * x.y());
  }
  const auto& c = solver.constraints();
  for (const auto& [node, ends] : hanging) {  // u* satisfies every hanging-node constraint, and the constraint
    EXPECT_TRUE(c.is_constrained(2 * node) && c.is_constrained(2 * node + 1));  // object holds them
    EXPECT_NEAR((ustar.segment<2>(2 * node) - 0.5 * (ustar.segment<2>(2 * ends.first) + ustar.segment<2>(2 * ends.second))).norm(),
                0.0, 1e-15);
  }
  const Eigen::VectorXd r = c.T().transpose() * (solver.stiffness() * ustar);
  const double scale = (solver.stiffness().cwiseAbs() * ustar.cwiseAbs()).maxCoeff();
  int interior = 0;
  for (int k = 0; k < c.n_free(); ++k) {
    const int dof = c.free_dofs()[static_cast<size_t>(k)];
    const auto& x = body.mesh.nodes[static_cast<size_t>(dof / 2)];
    if (x.x() <= 0 || x.x() >= 2 || x.y() <= 0 || x.y() >= 2) continue;
    ++interior;
    EXPECT_LE(std::abs(r[k]), 1e-12 * scale) << "dof " << dof;
  }
  EXPECT_GT(interior, 40);
}

TEST(HangingNodes, UniformStressUnderTractionsOnANonConformingMesh) {
  Body body = square_body("patch");
  refine_towards(body.mesh, mesh::Point(1.0, 1.0), 3);
  ASSERT_FALSE(mesh::hanging_nodes(body.mesh).empty());
  BoundaryCondition left{"left", BoundaryCondition::Kind::displacement};
  left.ux = 0.0;
  BoundaryCondition bottom{"bottom", BoundaryCondition::Kind::displacement};
  bottom.uy = 0.0;
  BoundaryCondition right{"right", BoundaryCondition::Kind::traction};
  right.traction = Eigen::Vector2d(30, 0);
  BoundaryCondition top{"top", BoundaryCondition::Kind::traction};
  top.traction = Eigen::Vector2d(0, -50);
  body.boundary = {left, bottom, right, top};
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << solver.error();
  const auto s = solver.stresses(solver.solve(Eigen::VectorXd()));
  for (int c = 0; c < body.mesh.num_cells(); ++c) {
    EXPECT_NEAR(s.cell(c, 0), 30.0, 1e-7);
    EXPECT_NEAR(s.cell(c, 1), -50.0, 1e-7);
    EXPECT_NEAR(s.cell(c, 2), 0.0, 1e-7);
  }
}

TEST(HangingNodes, SupportReactionsBalanceTheLoadsWhereHangingNodesTouchTheSupport) {
  // A square clamped along its bottom, refined three levels towards a point just above it, so that hanging nodes
  // sit on sides whose lower end is a supported node; tractions on the top and the right. Whatever the mesh, the
  // supports' reactions balance the applied loads exactly: a hanging node's residual belongs to its masters, the
  // supported ones among them (left out, the refined two-cylinder example's supports were 4 % off).
  Body body = square_body("clamped");
  refine_towards(body.mesh, mesh::Point(1.0, 0.05), 3);
  BoundaryCondition bottom{"bottom", BoundaryCondition::Kind::displacement};
  bottom.ux = 0.0;
  bottom.uy = 0.0;
  BoundaryCondition right{"right", BoundaryCondition::Kind::traction};
  right.traction = Eigen::Vector2d(30, 0);
  BoundaryCondition top{"top", BoundaryCondition::Kind::traction};
  top.traction = Eigen::Vector2d(0, -50);
  body.boundary = {bottom, right, top};
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << solver.error();
  // Some hanging node is constrained to a node of the bottom edge.
  bool touches = false;
  for (const auto& [node, ends] : mesh::hanging_nodes(body.mesh))
    for (const int end : {ends.first, ends.second})
      touches = touches || std::abs(body.mesh.nodes[static_cast<size_t>(end)].y()) < 1e-12;
  ASSERT_TRUE(touches);
  const Eigen::VectorXd r = solver.reactions(solver.solve(Eigen::VectorXd()), Eigen::VectorXd());
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (Eigen::Index d = 0; d < r.size(); d += 2) total += Eigen::Vector2d(r[d], r[d + 1]);
  EXPECT_NEAR(total.x(), -30.0 * 2, 1e-8);  // the right side's load, 2 long
  EXPECT_NEAR(total.y(), 50.0 * 2, 1e-8);   // the top's
}

TEST(HangingNodes, LameRingConvergesAtTheOptimalRateUnderUniformRefinement) {
  // The quarter ring under internal pressure (lame_ring.hpp). Q1 on the curved mesh: nodal displacement error
  // O(h^2).
  const contact::testing::LameRing ring;
  Body body = ring.body(ring.block(4, 4));
  std::vector<double> errors;
  for (int level = 0; level < 3; ++level) {
    if (level > 0) mesh::refine_uniform(body.mesh);
    fem::BodySolver solver(body, Model{});
    ASSERT_TRUE(solver.ok()) << solver.error();
    const Eigen::VectorXd u = solver.solve(Eigen::VectorXd());
    double err = 0;
    for (int n = 0; n < body.mesh.num_nodes(); ++n)
      err = std::max(err, (u.segment<2>(2 * n) - ring.exact(body.mesh.nodes[static_cast<size_t>(n)])).norm());
    errors.push_back(err / (ring.A() * ring.b + ring.B() / ring.a));
  }
  for (size_t k = 1; k < errors.size(); ++k) {
    const double rate = std::log2(errors[k - 1] / errors[k]);
    EXPECT_GT(rate, 1.8) << "level " << k << ": errors " << errors[k - 1] << " -> " << errors[k];
  }
  EXPECT_LT(errors.back(), 2e-3);
}
