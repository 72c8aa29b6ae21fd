// The marking that serves the contact (solver/adapt/contact_zones.cpp; docs/algorithm.md, "Marking that serves
// the contact"): the zones of a step's pairs, the band factor sqrt(l / h), the neighbourhood and the
// grading, by hand on a block.
#include "adapt/contact_zones.hpp"
#include "adapt/indicator.hpp"
#include "contact/mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace contact;

namespace {

// The block [0, 4] x [-1, 0] in 8 x 2 cells (h = 0.5), the contact on its top side.
mesh::Mesh block() {
  mesh::BlockSpec s;
  s.corners = {mesh::Point(0, -1), mesh::Point(4, -1), mesh::Point(4, 0), mesh::Point(0, 0)};
  s.nx = 8;
  s.ny = 2;
  return mesh::make_block(s);
}

// A step with one pair whose nodes at x = 0, 0.25, ..., 4 on y = 0 press with p = max(0, 1 - x) (zone [0, 1]),
// and one NaN pressure (a node outside the mortar zone).
Step step_with_zone() {
  PairField pair;
  const int n = 17;
  pair.position.resize(n, 2);
  pair.pressure.resize(n);
  for (int j = 0; j < n; ++j) {
    pair.position.row(j) << 0.25 * j, 0.0;
    pair.pressure[j] = std::max(0.0, 1.0 - 0.25 * j);
  }
  pair.pressure[n - 1] = std::nan("");
  Step step;
  step.pairs.push_back(pair);
  return step;
}

}  // namespace

TEST(ContactMarking, ZonesAreTheBoxesOfThePressedNodes) {
  const auto zones = adapt::contact_zones(step_with_zone());
  ASSERT_EQ(zones.size(), 1u);
  EXPECT_EQ(zones[0].lo, Eigen::Vector2d(0, 0));
  EXPECT_EQ(zones[0].hi, Eigen::Vector2d(0.75, 0));  // p(1) = 0 is not pressed
  EXPECT_DOUBLE_EQ(zones[0].distance(Eigen::Vector2d(1.75, -1)), std::sqrt(1.0 + 1.0));
  Step empty;
  empty.pairs.push_back(PairField{});
  EXPECT_TRUE(adapt::contact_zones(empty).empty());
}

TEST(ContactMarking, TheBandHoldsCellsAlongTheZoneToATighterDeltaAndTheGradingKeepsFarCells) {
  const mesh::Mesh m = block();
  const auto zones = adapt::contact_zones(step_with_zone());
  const adapt::ContactMarking rules = adapt::contact_marking(m, zones, 0.25);
  for (int c = 0; c < m.num_cells(); ++c) {
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (int k : m.cells[static_cast<size_t>(c)]) centre += 0.25 * m.nodes[static_cast<size_t>(k)];
    const double d = zones[0].distance(centre);
    // Within one cell size (0.5) of the zone the band's sqrt(l / h) with l = 0.75, h = 0.5, or the neighbourhood's 2
    // if larger (it is); within one extent (0.75) the neighbourhood's 2; elsewhere 1.
    const double band = d < 0.5 ? std::sqrt(0.75 / 0.5) : 1.0;
    EXPECT_DOUBLE_EQ(rules.factor[static_cast<size_t>(c)], d < 0.75 ? std::max(band, 2.0) : 1.0) << c;
    // Cells smaller than 0.25 x their distance: h = 0.5 < 0.25 d where d > 2.
    EXPECT_EQ(rules.graded[static_cast<size_t>(c)], d > 2.0) << c;
  }
  // Grading 0 keeps nothing; without zones the factors are 1.
  for (char g : adapt::contact_marking(m, zones, 0.0).graded) EXPECT_EQ(g, 0);
  for (double f : adapt::contact_marking(m, {}, 0.25).factor) EXPECT_EQ(f, 1.0);
}

TEST(ContactMarking, MarkLeavesGradedCellsAndCountsThem) {
  const mesh::Mesh m = block();
  const Eigen::VectorXd eta = Eigen::VectorXd::Constant(m.num_cells(), 0.2);
  std::vector<char> graded(static_cast<size_t>(m.num_cells()), 0);
  graded[3] = graded[7] = 1;
  const adapt::Marking marked = adapt::mark(m, eta, 0.1, 8, 400000, graded);
  EXPECT_EQ(marked.graded_out, 2);
  EXPECT_EQ(marked.cells.size(), static_cast<size_t>(m.num_cells() - 2));
  for (int c : marked.cells) EXPECT_FALSE(graded[static_cast<size_t>(c)]) << c;
}
