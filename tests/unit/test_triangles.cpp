// Linear triangles (P1) and mixed meshes: the element, patch tests on distorted triangle and mixed meshes,
// refinement of triangles with hanging nodes, the Lame ring's convergence rate, and both error indicators.
// Every expected number comes from mathematics: rigid modes, linear fields, exact solutions.
#include "adapt/indicator.hpp"
#include "fem/body_solver.hpp"
#include "fem/element.hpp"
#include "fem/triangle.hpp"
#include "contact/mesh.hpp"
#include "element_checks.hpp"
#include "lame_ring.hpp"
#include "refine_checks.hpp"
#include "triangle_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace contact;
using contact::testing::max_nodes_inside_a_side;
using contact::testing::refine_towards;
using contact::testing::split_into_triangles;

namespace {

mesh::Mesh block(int nx, int ny, double w = 3, double h = 2) {
  mesh::BlockSpec s;
  s.corners = {mesh::Point(0, 0), mesh::Point(w, 0), mesh::Point(w, h), mesh::Point(0, h)};
  s.nx = nx;
  s.ny = ny;
  return mesh::make_block(s);
}

// Interior nodes moved at random by up to 30 % of the spacing (the boundary stays straight).
void distort(mesh::Mesh& m, double amount, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> shift(-amount, amount);
  const auto lo = m.bbox_min(), hi = m.bbox_max();
  for (auto& p : m.nodes) {
    const bool boundary = p.x() <= lo.x() || p.x() >= hi.x() || p.y() <= lo.y() || p.y() >= hi.y();
    if (!boundary) p += Eigen::Vector2d(shift(rng), shift(rng));
  }
}

double total_area(const mesh::Mesh& m) {
  double a = 0;
  for (int c = 0; c < m.num_cells(); ++c) a += m.cell_area(c);
  return a;
}

// u* = a + G x, with shear and rotation.
Eigen::Vector2d linear_field(const Eigen::Vector2d& x) {
  Eigen::Matrix2d G;
  G << 1.0e-3, 4.0e-4, -2.0e-4, -6.0e-4;
  return Eigen::Vector2d(2e-3, -1e-3) + G * x;
}

// The patch test with u* prescribed on the whole boundary (every node of the four block edges): the FE solution
// must be u* at every node and its stresses D eps(u*) in every cell.
void expect_linear_field_is_exact(const mesh::Mesh& m, const std::string& what) {
  Body body;
  body.name = "patch";
  body.material = {2.1e5, 0.3};
  body.mesh = m;
  // The FE solution with u = u* on the boundary is u* + w, w = 0 on the boundary and K w = -K u* at the free
  // unknowns: w is the homogeneous response to the load -K u*, and it must vanish.
  for (const char* edge : {"bottom", "right", "top", "left"}) {
    BoundaryCondition bc{edge, BoundaryCondition::Kind::displacement};
    bc.ux = 0.0;
    bc.uy = 0.0;
    body.boundary.push_back(bc);
  }
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << what << ": " << solver.error();
  Eigen::VectorXd ustar(2 * m.num_nodes());
  for (int n = 0; n < m.num_nodes(); ++n) ustar.segment<2>(2 * n) = linear_field(m.nodes[static_cast<size_t>(n)]);
  const Eigen::VectorXd w = solver.solve_homogeneous(-(solver.stiffness() * ustar));
  EXPECT_LE(w.cwiseAbs().maxCoeff(), 1e-12 * ustar.cwiseAbs().maxCoeff()) << what;
  const auto s = solver.stresses(ustar);
  const Eigen::Vector3d exact = solver.elasticity().D * Eigen::Vector3d(1.0e-3, -6.0e-4, 4.0e-4 - 2.0e-4);
  for (int c = 0; c < m.num_cells(); ++c)
    EXPECT_LE((s.cell.row(c).head<3>().transpose() - exact).norm(), 1e-9 * exact.norm()) << what << ", cell " << c;
  for (int n = 0; n < m.num_nodes(); ++n)
    EXPECT_LE((s.node.row(n).head<3>().transpose() - exact).norm(), 1e-9 * exact.norm()) << what << ", node " << n;
}

}  // namespace

TEST(P1Element, StiffnessIsSymmetricWithExactlyThreeRigidModesInItsNullSpace) {
  Eigen::Matrix<double, 3, 2> x;
  x << 0.1, 0.2, 1.3, -0.1, 0.4, 0.9;
  for (Plane plane : {Plane::strain, Plane::stress}) {
    const fem::Elasticity el = fem::make_elasticity({2.1e5, 0.3}, Model{plane, 0.5});
    contact::testing::expect_symmetric_with_rigid_null_space<3>(fem::triangle_stiffness(x, el), x);
  }
}

TEST(P1Element, StrainOfALinearFieldAndBodyForceAreExact) {
  Eigen::Matrix<double, 3, 2> x;
  x << 0.1, 0.2, 1.3, -0.1, 0.4, 0.9;
  const double area = 0.5 * ((1.3 - 0.1) * (0.9 - 0.2) - (0.4 - 0.1) * (-0.1 - 0.2));
  const fem::Elasticity el = fem::make_elasticity({2.1e5, 0.3}, Model{Plane::stress, 0.5});
  fem::Vector6d u;
  for (int k = 0; k < 3; ++k) u.segment<2>(2 * k) = linear_field(x.row(k).transpose());
  double signed_area = 0;
  const Eigen::Vector3d strain = fem::triangle_strain_matrix(x, signed_area) * u;
  EXPECT_NEAR(signed_area, area, 1e-15);
  EXPECT_LE((strain - Eigen::Vector3d(1.0e-3, -6.0e-4, 2.0e-4)).norm(), 1e-15);
  // The consistent load of a constant force: integral of N_k = |T| / 3 at each node, thickness included.
  const fem::Vector6d f = fem::triangle_body_force(x, Eigen::Vector2d(3.0, -7.0), el);
  for (int k = 0; k < 3; ++k) EXPECT_LE((f.segment<2>(2 * k) - Eigen::Vector2d(3.0, -7.0) * area * 0.5 / 3).norm(), 1e-14);
}

TEST(P1PatchTest, LinearFieldIsExactOnDistortedTriangleAndMixedMeshes) {
  mesh::Mesh quads = block(6, 5);
  distort(quads, 0.15);
  const mesh::Mesh triangles = split_into_triangles(quads);
  ASSERT_TRUE(mesh::check_cells(triangles).empty());
  ASSERT_EQ(triangles.num_cells(), 60);
  expect_linear_field_is_exact(triangles, "triangles");
  // Mixed: every third quadrilateral split.
  const mesh::Mesh mixed = split_into_triangles(quads, [](int c) { return c % 3 == 0; });
  ASSERT_TRUE(mesh::check_cells(mixed).empty());
  ASSERT_EQ(mixed.num_cells(), 40);
  ASSERT_TRUE(mixed.has_triangles());
  expect_linear_field_is_exact(mixed, "mixed");
}

TEST(P1PatchTest, TractionsGiveUniformStressAndBalancedReactionsOnAMixedMesh) {
  // The traction patch test of the Q1 element (element_checks.hpp), the top loaded as a normal pressure.
  mesh::Mesh quads = block(6, 5);
  distort(quads, 0.15, 11);
  contact::testing::expect_uniform_traction_state(
      contact::testing::uniform_traction_body(split_into_triangles(quads, [](int c) { return c % 2 == 1; }), true));
}

TEST(P1PatchTest, BodyForceIsBalancedByTheReactions) {
  // A body force f per volume on a mixed mesh of area 6, held on every edge: the reactions carry it all.
  Body body;
  body.name = "weight";
  body.material = {2.1e5, 0.3};
  body.mesh = split_into_triangles(block(6, 4), [](int c) { return c % 2 == 0; });
  body.body_force = Eigen::Vector2d(2.0, -9.0);
  BoundaryCondition fixed{"bottom", BoundaryCondition::Kind::displacement};
  fixed.ux = 0.0;
  fixed.uy = 0.0;
  body.boundary = {fixed};
  fem::BodySolver solver(body, Model{Plane::stress, 0.25});
  ASSERT_TRUE(solver.ok()) << solver.error();
  const Eigen::VectorXd R = solver.reactions(solver.solve(Eigen::VectorXd()), Eigen::VectorXd());
  Eigen::Vector2d total = Eigen::Vector2d::Zero();
  for (int n = 0; n < body.mesh.num_nodes(); ++n) total += R.segment<2>(2 * n);
  EXPECT_LE((total + 6.0 * 0.25 * body.body_force).norm(), 1e-9 * 6.0 * 0.25 * 9.0);
}

TEST(TriangleRefinement, SplitsIntoFourKeepsAreaAndEdgeSetsAndStaysOneIrregular) {
  mesh::Mesh m = split_into_triangles(block(2, 2, 2, 2));
  const auto r = mesh::refine(m, {0});
  EXPECT_EQ(r.refined_cells, 1);
  EXPECT_EQ(m.num_cells(), 8 + 3);
  EXPECT_NEAR(total_area(m), 4.0, 1e-14);
  EXPECT_TRUE(mesh::check_cells(m).empty());
  const auto bottom = m.edge_set_nodes("bottom");
  ASSERT_EQ(bottom.size(), 4u);  // 0, 0.5, 1, 2
  for (size_t k = 0; k + 1 < bottom.size(); ++k) EXPECT_LT(m.nodes[bottom[k]].x(), m.nodes[bottom[k + 1]].x());
  // Cell 0 = (0,0) (1,0) (1,1): its sides to the right and along the diagonal now have hanging nodes.
  EXPECT_EQ(mesh::hanging_nodes(m).size(), 2u);
  // Local refinement towards a point, on triangles and on a mixed mesh: the closure keeps one hanging node per
  // side at most, across triangles and quadrilaterals.
  for (const bool mixed : {false, true}) {
    mesh::Mesh t = split_into_triangles(block(3, 3, 2, 2), [mixed](int c) { return !mixed || c % 2 == 0; });
    refine_towards(t, mesh::Point(0.3, 0.01), 5);
    EXPECT_LE(max_nodes_inside_a_side(t), 1) << (mixed ? "mixed" : "triangles");
    EXPECT_TRUE(mesh::check_cells(t).empty());
    EXPECT_NEAR(total_area(t), 4.0, 1e-12);
    EXPECT_EQ(*std::max_element(t.level.begin(), t.level.end()), 5);
  }
}

TEST(TriangleRefinement, TransferReproducesALinearFieldAtTheNewNodes) {
  mesh::Mesh m = split_into_triangles(block(3, 3), [](int c) { return c != 4; });
  auto field = [](const mesh::Point& x) { return 1.0 + 2.0 * x.x() - 0.5 * x.y(); };
  Eigen::MatrixXd u(m.num_nodes(), 1);
  for (int n = 0; n < m.num_nodes(); ++n) u(n, 0) = field(m.nodes[static_cast<size_t>(n)]);
  const auto r = mesh::refine(m, {0, 4, 8, 11});
  const Eigen::MatrixXd v = mesh::transfer(u, r, m.num_nodes());
  for (int n = 0; n < m.num_nodes(); ++n) EXPECT_NEAR(v(n, 0), field(m.nodes[static_cast<size_t>(n)]), 1e-13);
}

TEST(TriangleRefinement, PatchTestHoldsWithHangingNodesOnTriangleAndMixedMeshes) {
  for (const bool mixed : {false, true}) {
    mesh::Mesh m = split_into_triangles(block(4, 3), [mixed](int c) { return !mixed || c % 2 == 1; });
    refine_towards(m, mesh::Point(0.9, 1.1), 3);
    refine_towards(m, mesh::Point(2.2, 0.4), 2);
    ASSERT_GE(mesh::hanging_nodes(m).size(), 6u);
    expect_linear_field_is_exact(m, mixed ? "refined mixed" : "refined triangles");
  }
}

TEST(TriangleRefinement, LameRingConvergesAtSecondOrderInTheNodalDisplacements) {
  // The quarter ring under internal pressure (lame_ring.hpp) on triangles and on a mixed mesh, refined uniformly
  // (new boundary nodes on the arcs).
  const contact::testing::LameRing ring;
  for (const bool mixed : {false, true}) {
    Body body = ring.body(split_into_triangles(ring.block(4, 6), [mixed](int c) { return !mixed || c % 3 != 0; }));
    std::vector<double> rms, max;  // relative to the largest displacement
    for (int level = 0; level < 4; ++level) {
      if (level > 0) mesh::refine_uniform(body.mesh);
      fem::BodySolver solver(body, Model{});
      ASSERT_TRUE(solver.ok()) << solver.error();
      const Eigen::VectorXd u = solver.solve(Eigen::VectorXd());
      double sum = 0, worst = 0;
      for (int n = 0; n < body.mesh.num_nodes(); ++n) {
        const double e = (u.segment<2>(2 * n) - ring.exact(body.mesh.nodes[static_cast<size_t>(n)])).norm();
        sum += e * e;
        worst = std::max(worst, e);
      }
      rms.push_back(std::sqrt(sum / body.mesh.num_nodes()) / ring.scale());
      max.push_back(worst / ring.scale());
    }
    // The discrete L2 error falls like h^2 (measured rates 1.92, 1.96, 1.99 on triangles; 1.80, 1.92, 1.98 on the
    // mixed mesh, whose first step is not yet asymptotic); the maximum like h^2 |ln h| (Nitsche), whose rate
    // approaches 2 from below (1.5 to 1.8 at these sizes).
    for (size_t k = 1; k < rms.size(); ++k) {
      const std::string what = std::string(mixed ? "mixed" : "triangles") + ", level " + std::to_string(k);
      const double rate = std::log2(rms[k - 1] / rms[k]);
      EXPECT_GT(rate, k + 1 == rms.size() ? 1.95 : 1.75) << what << ": rms " << rms[k - 1] << " -> " << rms[k];
      EXPECT_GT(std::log2(max[k - 1] / max[k]), 1.45) << what << ": max " << max[k - 1] << " -> " << max[k];
    }
    EXPECT_LT(max.back(), 2e-3) << (mixed ? "mixed" : "triangles");
  }
}

TEST(TriangleIndicators, BothIndicatorsVanishForTheExactUniformStateAndFindALocalError) {
  // The uniform state of the traction patch test is exact for P1: its FE stresses equal the recovered ones (zz)
  // and the boundary-element ones (fem_bem) up to the BEM's own error.
  mesh::Mesh quads = block(6, 4);
  distort(quads, 0.12, 3);
  Body body = contact::testing::uniform_traction_body(split_into_triangles(quads, [](int c) { return c % 2 == 0; }),
                                                      false);
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << solver.error();
  const Eigen::VectorXd u = solver.solve(Eigen::VectorXd());
  const Eigen::VectorXd none = Eigen::VectorXd::Zero(u.size());
  const auto zz = adapt::zz_indicator(body, solver, u);
  ASSERT_EQ(zz.eta.size(), body.mesh.num_cells());
  EXPECT_LE(zz.eta.maxCoeff(), 1e-9);
  const auto fb = adapt::fem_bem_indicator(body, Model{}, solver, u, none);
  EXPECT_TRUE(fb.note.empty()) << fb.note;
  ASSERT_EQ(fb.eta.size(), body.mesh.num_cells());
  EXPECT_LE(fb.eta.maxCoeff(), 0.02);  // the BEM's discretisation error, far below the default delta 0.1
  // A point load at a corner of the top (a traction on one short edge): both indicators are largest there.
  body.mesh = split_into_triangles(block(6, 4), [](int c) { return c % 2 == 0; });
  mesh::refine(body.mesh, {23});  // the top-right cell, split: its top side is a short edge of its own
  std::vector<std::array<int, 2>> corner;
  const auto top = body.mesh.edge_set_nodes("top");
  corner.push_back({top[0], top[1]});
  ASSERT_FALSE(mesh::add_edge_set(body.mesh, "corner", corner).has_value());
  BoundaryCondition load{"corner", BoundaryCondition::Kind::traction};
  load.traction = Eigen::Vector2d(0, -100);
  body.boundary.resize(2);  // the supports on the left and the bottom
  body.boundary.push_back(load);
  fem::BodySolver loaded(body, Model{});
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  const Eigen::VectorXd v = loaded.solve(Eigen::VectorXd());
  for (const auto& eta : {adapt::zz_indicator(body, loaded, v).eta,
                          adapt::fem_bem_indicator(body, Model{}, loaded, v, Eigen::VectorXd::Zero(v.size())).eta}) {
    Eigen::Index worst = 0;
    eta.maxCoeff(&worst);
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (int k : body.mesh.cells[static_cast<size_t>(worst)]) centre += body.mesh.nodes[static_cast<size_t>(k)];
    centre /= body.mesh.cells[static_cast<size_t>(worst)].size();
    EXPECT_LT((centre - Eigen::Vector2d(3.0, 2.0)).norm(), 0.75) << "largest eta at " << centre.transpose();
  }
}

TEST(TriangleIndicators, FemBemOnABodyHeldAtVerticesOnlyPinsItsRigidMotionInsteadOfFallingBackToZz) {
  // The uniform traction state with tractions on all four sides and the body held at two vertices only (bottom
  // left in x and y, bottom right in y: supports that carry nothing in this state). The edge conditions alone leave
  // the boundary-element problem free to translate and rotate; the FE displacement pins that (indicator.cpp,
  // pin_rigid_motions), so fem_bem runs (no fallback note), its stresses match the exact FE ones to the BEM's own
  // error, and its boundary displacements are the FE ones (exact here) to the same accuracy. Before, such a body
  // fell back to zz and had no boundary-element displacements (no pressure estimate).
  Body body = contact::testing::uniform_traction_body(block(6, 4), false);
  body.boundary.resize(2);  // right and top tractions below; left and bottom become tractions too
  BoundaryCondition left{"left", BoundaryCondition::Kind::traction}, bottom{"bottom", BoundaryCondition::Kind::traction};
  left.traction = Eigen::Vector2d(-contact::testing::kPatchSxx, 0);
  bottom.traction = Eigen::Vector2d(0, -contact::testing::kPatchSyy);
  BoundaryCondition right{"right", BoundaryCondition::Kind::traction}, top{"top", BoundaryCondition::Kind::traction};
  right.traction = Eigen::Vector2d(contact::testing::kPatchSxx, 0);
  top.traction = Eigen::Vector2d(0, contact::testing::kPatchSyy);
  BoundaryCondition pin{"", BoundaryCondition::Kind::displacement}, roller{"", BoundaryCondition::Kind::displacement};
  pin.vertex = "bottom_left";
  pin.ux = pin.uy = 0.0;
  roller.vertex = "bottom_right";
  roller.uy = 0.0;
  body.boundary = {left, bottom, right, top, pin, roller};
  fem::BodySolver solver(body, Model{});
  ASSERT_TRUE(solver.ok()) << solver.error();
  const Eigen::VectorXd u = solver.solve(Eigen::VectorXd());
  const auto fb = adapt::fem_bem_indicator(body, Model{}, solver, u, Eigen::VectorXd::Zero(u.size()));
  EXPECT_TRUE(fb.note.empty()) << fb.note;
  ASSERT_EQ(fb.eta.size(), body.mesh.num_cells());
  EXPECT_LE(fb.eta.maxCoeff(), 0.02);
  ASSERT_EQ(fb.bem_displacement.size(), u.size());
  EXPECT_LE((fb.bem_displacement - u).cwiseAbs().maxCoeff(), 0.01 * u.cwiseAbs().maxCoeff());
}
