// Mesh module: block generator geometry, curved edges on their curves, grading, edge sets, cell checks.
#include "contact/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace contact::mesh;

namespace {
BlockSpec unit_block(int nx, int ny) {
  BlockSpec s;
  s.corners = {Point(0, 0), Point(4, 0), Point(4, 1), Point(0, 1)};
  s.nx = nx;
  s.ny = ny;
  return s;
}
}  // namespace

TEST(BlockMesh, CountsAndEdgeSetsFollowTheBoundaryCounterClockwise) {
  Mesh m = make_block(unit_block(4, 2));
  EXPECT_EQ(m.num_nodes(), 15);
  EXPECT_EQ(m.num_cells(), 8);
  ASSERT_EQ(m.edge_sets.at("bottom").size(), 4u);
  ASSERT_EQ(m.edge_sets.at("right").size(), 2u);
  const auto bottom = m.edge_set_nodes("bottom");
  ASSERT_EQ(bottom.size(), 5u);
  for (size_t k = 0; k + 1 < bottom.size(); ++k) EXPECT_LT(m.nodes[bottom[k]].x(), m.nodes[bottom[k + 1]].x());
  const auto top = m.edge_set_nodes("top");
  for (size_t k = 0; k + 1 < top.size(); ++k) EXPECT_GT(m.nodes[top[k]].x(), m.nodes[top[k + 1]].x());
  for (int c = 0; c < m.num_cells(); ++c) EXPECT_NEAR(m.cell_area(c), 0.5, 1e-14);
  EXPECT_TRUE(check_cells(m).empty());
}

TEST(BlockMesh, GradingMakesElementsGeometricWithTheRequestedRatio) {
  BlockSpec s = unit_block(5, 1);
  s.grading["left"] = 16.0;
  Mesh m = make_block(s);
  const auto b = m.edge_set_nodes("bottom");
  const double first = m.nodes[b[1]].x() - m.nodes[b[0]].x();
  const double last = m.nodes[b[5]].x() - m.nodes[b[4]].x();
  EXPECT_NEAR(last / first, 16.0, 1e-10);
  EXPECT_NEAR(m.nodes[b[5]].x(), 4.0, 1e-14);
}

TEST(BlockMesh, ParabolaEdgeNodesLieOnTheCurve) {
  BlockSpec s = unit_block(8, 2);
  s.corners[0] = Point(0, 0);
  s.corners[1] = Point(4, 0.016);
  Curve c;
  c.kind = Curve::Kind::parabola;
  c.a = 0.001;
  ASSERT_FALSE(fit_curve(c, s.corners[0], s.corners[1]).has_value());
  s.curves["bottom"] = c;
  Mesh m = make_block(s);
  for (int n : m.edge_set_nodes("bottom")) EXPECT_NEAR(m.nodes[n].y(), 0.001 * m.nodes[n].x() * m.nodes[n].x(), 1e-15);
  EXPECT_TRUE(check_cells(m).empty());
}

TEST(BlockMesh, ArcEdgeNodesLieOnTheCircle) {
  BlockSpec s;
  s.corners = {Point(1, 0), Point(2, 0), Point(0, 2), Point(0, 1)};
  s.nx = 3;
  s.ny = 6;
  Curve outer, inner;
  outer.kind = inner.kind = Curve::Kind::arc;
  outer.radius = 2;
  inner.radius = 1;
  ASSERT_FALSE(fit_curve(outer, s.corners[1], s.corners[2]).has_value());
  ASSERT_FALSE(fit_curve(inner, s.corners[0], s.corners[3]).has_value());
  s.curves["right"] = outer;
  s.curves["left"] = inner;
  Mesh m = make_block(s);
  for (int n : m.edge_set_nodes("right")) EXPECT_NEAR(m.nodes[n].norm(), 2.0, 1e-14);
  for (int n : m.edge_set_nodes("left")) EXPECT_NEAR(m.nodes[n].norm(), 1.0, 1e-14);
  EXPECT_TRUE(check_cells(m).empty());
}

TEST(MeshChecks, ReportInvertedAndDegenerateCells) {
  Mesh m;
  m.nodes = {Point(0, 0), Point(1, 0), Point(1, 1), Point(0, 1), Point(2, 0)};
  m.cells = {{0, 3, 2, 1}, {0, 1, 1, 3}};
  m.level = {0, 0};
  const auto problems = check_cells(m);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("cell 0 is inverted"), std::string::npos);
  EXPECT_NE(problems[1].find("cell 1"), std::string::npos);
}

TEST(EdgeSets, ExplicitPairsAreOrderedIntoAChainAndInteriorSidesRejected) {
  Mesh m = make_block(unit_block(3, 1));
  Mesh e;
  e.nodes = m.nodes;
  e.cells = m.cells;
  e.level = m.level;
  // bottom nodes 0..3 given out of order and reversed
  ASSERT_FALSE(add_edge_set(e, "b", {{{2, 3}}, {{1, 0}}, {{1, 2}}}).has_value());
  EXPECT_EQ(e.edge_set_nodes("b"), (std::vector<int>{0, 1, 2, 3}));
  auto err = add_edge_set(e, "bad", {{{1, 5}}});
  ASSERT_TRUE(err.has_value());
  EXPECT_NE(err->find("interior"), std::string::npos);
}
