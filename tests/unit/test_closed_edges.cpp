// Closed contact curves (issue 29, item 2) module by module: an edge set that is a closed loop (a bore, a shaft's
// rim) accepted and ordered, kept by refinement; a set of several pieces still refused; the mortar pair of two
// loops without ends; where a contact zone lies on a loop.
#include "contact/job.hpp"
#include "contact_extent.hpp"
#include "mortar/pair.hpp"
#include "polar_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace contact;
using namespace contact::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Twice the signed area of the polygon through the nodes (positive when they run counter-clockwise).
double signed_area(const mesh::Mesh& m, const std::vector<int>& nodes) {
  double a = 0;
  for (size_t k = 0; k < nodes.size(); ++k) {
    const auto& p = m.nodes[static_cast<size_t>(nodes[k])];
    const auto& q = m.nodes[static_cast<size_t>(nodes[(k + 1) % nodes.size()])];
    a += p.x() * q.y() - p.y() * q.x();
  }
  return a;
}

// An annulus as an explicit job mesh: its nodes, quads, the edges "bore" (the inner circle) and "outside", and its
// vertices.
nlohmann::json explicit_annulus(double a, double b, int nr, int nt) {
  const PolarMesh p = polar_annulus(a, b, nr, nt);
  nlohmann::json nodes = nlohmann::json::array(), quads = nlohmann::json::array();
  for (const auto& x : p.mesh.nodes) nodes.push_back({x.x(), x.y()});
  for (const auto& c : p.mesh.cells) quads.push_back({c[0], c[1], c[2], c[3]});
  return {{"nodes", nodes}, {"quads", quads}, {"edges", {{"bore", p.inner}, {"outside", p.outer}}},
          {"vertices", p.mesh.vertices}};
}

}  // namespace

TEST(ClosedEdges, AnExplicitJobNamesALoopAndItsFloatingBodyIsHeldAllRoundButSpinsWithoutFriction) {
  // A tube (250 .. 500) in a ring (500 .. 1000), both explicit meshes with closed edges, the ring held at three
  // outer vertices, the tube only by the contact of its "outside" loop with the ring's "bore". Frictionless, the
  // loop's radial normals hold the tube's translations, the start's included, but not its rotation about the
  // centre, and the reader says so; with friction the job is accepted.
  nlohmann::json job = {
      {"name", "tube_in_ring"}, {"version", 1},
      {"bodies",
       {{{"name", "tube"}, {"material", {{"E", 2e5}, {"nu", 0.3}}}, {"mesh", explicit_annulus(250, 500, 4, 32)}},
        {{"name", "ring"}, {"material", {{"E", 2e5}, {"nu", 0.3}}}, {"mesh", explicit_annulus(500, 1000, 4, 32)},
         {"boundary",
          {{{"vertex", "east"}, {"displacement", {{"y", 0}}}}, {{"vertex", "west"}, {"displacement", {{"y", 0}}}},
           {{"vertex", "north"}, {"displacement", {{"x", 0}}}}}}}}},
      {"contacts", {{{"slave", "ring.bore"}, {"master", "tube.outside"}, {"gap", {{"constant", -0.5}}}}}}};
  auto parsed = job::parse(job);
  ASSERT_FALSE(parsed.ok());
  const std::string errors = job::format_errors(parsed.errors);
  EXPECT_NE(errors.find("body 'tube' floats"), std::string::npos) << errors;
  EXPECT_NE(errors.find("nothing resists its rotation about (0, 0) (it spins: every contact normal passes through "
                        "that point); prescribe"),
            std::string::npos) << errors;  // its rotation only, no translation
  job["contacts"][0]["friction"] = {{"coefficient", 0.3}};
  parsed = job::parse(job);
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  for (const auto& [body, edge] : {std::pair{0, "outside"}, std::pair{1, "bore"}}) {
    const mesh::Mesh& m = parsed.problem->bodies[static_cast<size_t>(body)].mesh;
    EXPECT_TRUE(m.edge_set_closed(edge)) << edge;
    EXPECT_EQ(m.edge_set_nodes(edge).size(), 32u) << edge;
  }
}

TEST(ClosedEdges, ARingOfQuadsAroundAHoleGivesTwoLoopsOrderedWithTheBodyOnTheLeftFromTheFirstSideGiven) {
  PolarMesh p = polar_annulus(1.0, 2.0, 2, 8);  // inner nodes 0..7, outer 16..23
  // The hole's circle in a shuffled order, either orientation: its first pair [5, 4] runs 5 -> 4 in its cell
  // (the body on the left goes clockwise round a hole), so the loop starts at node 5.
  std::vector<std::array<int, 2>> hole = {{5, 4}, {1, 2}, {7, 0}, {3, 2}, {6, 5}, {0, 1}, {4, 3}, {6, 7}};
  ASSERT_FALSE(mesh::add_edge_set(p.mesh, "bore", hole).has_value());
  EXPECT_TRUE(p.mesh.edge_set_closed("bore"));
  EXPECT_EQ(p.mesh.edge_set_nodes("bore"), (std::vector<int>{5, 4, 3, 2, 1, 0, 7, 6}));
  EXPECT_LT(signed_area(p.mesh, p.mesh.edge_set_nodes("bore")), 0);  // clockwise round the hole
  // The outer circle from [18, 17]: its side runs 17 -> 18 (counter-clockwise round the body).
  std::vector<std::array<int, 2>> outside = p.outer;
  std::rotate(outside.begin(), outside.begin() + 1, outside.end());
  outside.front() = {18, 17};
  ASSERT_FALSE(mesh::add_edge_set(p.mesh, "outside", outside).has_value());
  EXPECT_TRUE(p.mesh.edge_set_closed("outside"));
  EXPECT_EQ(p.mesh.edge_set_nodes("outside"), (std::vector<int>{17, 18, 19, 20, 21, 22, 23, 16}));
  EXPECT_GT(signed_area(p.mesh, p.mesh.edge_set_nodes("outside")), 0);
  // Consecutive sides share their node, the last side closes the loop.
  const auto& refs = p.mesh.edge_sets.at("bore");
  for (size_t k = 0; k < refs.size(); ++k)
    EXPECT_EQ(p.mesh.edge_nodes(refs[k])[1], p.mesh.edge_nodes(refs[(k + 1) % refs.size()])[0]) << k;
  // An open chain stays open: n sides, n + 1 nodes.
  ASSERT_FALSE(mesh::add_edge_set(p.mesh, "arc", {{{0, 1}}, {{1, 2}}}).has_value());
  EXPECT_FALSE(p.mesh.edge_set_closed("arc"));
  EXPECT_EQ(p.mesh.edge_set_nodes("arc"), (std::vector<int>{2, 1, 0}));
}

TEST(ClosedEdges, RefinementKeepsALoopClosedWithItsStartAndItsOrder) {
  PolarMesh p = polar_annulus(1.0, 2.0, 2, 8);
  ASSERT_FALSE(mesh::add_edge_set(p.mesh, "bore", p.inner).has_value());
  const std::vector<int> before = p.mesh.edge_set_nodes("bore");
  mesh::refine_uniform(p.mesh);
  ASSERT_TRUE(p.mesh.edge_set_closed("bore"));
  const std::vector<int> after = p.mesh.edge_set_nodes("bore");
  ASSERT_EQ(after.size(), 2 * before.size());
  for (size_t k = 0; k < before.size(); ++k) EXPECT_EQ(after[2 * k], before[k]) << k;  // the old nodes, in order
  // The new ones halfway between (on the chord: an explicit mesh names no curve).
  for (size_t k = 0; k < before.size(); ++k) {
    const auto mid = 0.5 * (p.mesh.nodes[static_cast<size_t>(before[k])] + p.mesh.nodes[static_cast<size_t>(before[(k + 1) % before.size()])]);
    EXPECT_LT((p.mesh.nodes[static_cast<size_t>(after[2 * k + 1])] - mid).norm(), 1e-14) << k;
  }
}

TEST(ClosedEdges, SeveralPiecesAreStillRefusedWithTheirMessage) {
  PolarMesh p = polar_annulus(1.0, 2.0, 2, 8);
  // Both circles: two loops (the first pair, [0, 1], runs 1 -> 0 round the hole: the loop found from node 1).
  std::vector<std::array<int, 2>> both = p.inner;
  both.insert(both.end(), p.outer.begin(), p.outer.end());
  auto err = mesh::add_edge_set(p.mesh, "both", both);
  ASSERT_TRUE(err.has_value());
  EXPECT_NE(err->find("its 16 sides are not one chain along the boundary: they form several closed loops (one of 8 sides through (0.707107, 0.707107))"),
            std::string::npos) << *err;
  // Two arcs of one circle: two open pieces, as before.
  err = mesh::add_edge_set(p.mesh, "arcs", {{{0, 1}}, {{1, 2}}, {{4, 5}}});
  ASSERT_TRUE(err.has_value());
  EXPECT_NE(err->find("its 3 sides are not one chain along the boundary: they form 2 separate pieces"), std::string::npos) << *err;
  // A loop and an arc of the other circle.
  std::vector<std::array<int, 2>> loop_and_arc = p.inner;
  loop_and_arc.push_back({16, 17});
  err = mesh::add_edge_set(p.mesh, "mixed", loop_and_arc);
  ASSERT_TRUE(err.has_value());
  EXPECT_NE(err->find("separate pieces"), std::string::npos) << *err;
  EXPECT_EQ(p.mesh.edge_sets.count("both") + p.mesh.edge_sets.count("arcs") + p.mesh.edge_sets.count("mixed"), 0u);
}

TEST(ClosedEdges, TheMortarPairOfTwoMatchingLoopsHasNoEnds) {
  // The full shrink fit's meshes, 64 nodes round the interface: every slave node a contact node, the start
  // included (no end treatment), each with the same weight (the meshes are unchanged by a rotation through one
  // node), the rows covering the polygon exactly once, and the weighted normals radial.
  const int nt = 64;
  const FullShrinkFit fit;
  for (const bool ring_slave : {true, false}) {
    const Problem problem = fit.problem(nt, nt, ring_slave);
    ASSERT_EQ(problem.bodies.size(), 2u);
    const auto d = mortar::discretize_pair(problem, 0, 1.0);
    const double side = 2 * fit.a * std::sin(kPi / nt), perimeter = nt * side;
    ASSERT_EQ(d.slave_nodes.size(), static_cast<size_t>(nt));
    ASSERT_EQ(d.master_nodes.size(), static_cast<size_t>(nt));
    EXPECT_TRUE(d.closed);
    EXPECT_NEAR(d.loop_length, perimeter, 1e-10 * perimeter);
    EXPECT_EQ(d.n_rows(), nt);
    EXPECT_EQ(d.multiplier_nodes.front(), 0u);
    EXPECT_EQ(d.multiplier_nodes.back(), static_cast<size_t>(nt));  // the start again
    ASSERT_EQ(d.status.size(), static_cast<size_t>(nt));
    ASSERT_EQ(d.node_arc.size(), nt);
    for (int i = 0; i < nt; ++i) {
      EXPECT_EQ(d.status[static_cast<size_t>(i)], mortar::NodeStatus::contact) << i;
      EXPECT_NEAR(d.node_arc[i], i * side, 1e-9 * perimeter) << i;
      EXPECT_NEAR(d.D[i], side, 1e-10 * side) << i;
      EXPECT_NEAR(d.area[i], side, 1e-10 * side) << i;
      const auto x = problem.bodies[static_cast<size_t>(d.slave_body)].mesh.nodes[static_cast<size_t>(d.slave_nodes[static_cast<size_t>(d.node_of_row[static_cast<size_t>(i)])])];
      const Eigen::Vector2d radial = x.normalized() * (ring_slave ? -1.0 : 1.0);  // outward of the slave
      EXPECT_NEAR(d.normal[static_cast<size_t>(i)].dot(radial), 1.0, 1e-12) << i;
    }
    // Conservative: each row's master integrals sum to its area; the constant gap is the constant everywhere.
    const Eigen::VectorXd row_sums = d.M * Eigen::VectorXd::Ones(d.M.cols());
    for (Eigen::Index r = 0; r < d.n_rows(); ++r) EXPECT_NEAR(row_sums[r], d.area[r], 1e-10 * side) << r;
    const Eigen::VectorXd g = d.nodal_gap(Eigen::VectorXd::Zero(d.Gs.cols()), Eigen::VectorXd::Zero(d.Gm.cols()));
    for (Eigen::Index r = 0; r < g.size(); ++r) EXPECT_NEAR(g[r], -fit.delta, 1e-9) << r;
    // A uniform pressure gives the slave no resultant (the loop closes).
    EXPECT_LT(d.resultant(Eigen::VectorXd::Ones(d.n_rows())).norm(), 1e-10 * perimeter);
  }
}

TEST(ClosedEdges, ANonMatchingLoopIsCoveredAllRound) {
  // 48 shaft nodes against 64 ring nodes, either side the slave: every slave node a contact node, the rows
  // covering the slave polygon once (the master's projection wraps round its start).
  const FullShrinkFit fit;
  for (const bool ring_slave : {true, false}) {
    const Problem problem = fit.problem(48, 64, ring_slave);
    const auto d = mortar::discretize_pair(problem, 0, 1.0);
    const int n = ring_slave ? 64 : 48;
    EXPECT_EQ(static_cast<int>(d.slave_nodes.size()), n);
    for (size_t i = 0; i < d.status.size(); ++i)
      EXPECT_TRUE(d.status[i] == mortar::NodeStatus::contact || d.status[i] == mortar::NodeStatus::inner) << i;
    EXPECT_NEAR(d.area.sum(), d.loop_length, 1e-9 * d.loop_length);
    EXPECT_NEAR(d.covered_length, d.loop_length, 1e-9 * d.loop_length);
    const Eigen::VectorXd row_sums = d.M * Eigen::VectorXd::Ones(d.M.cols());
    for (Eigen::Index r = 0; r < d.n_rows(); ++r) EXPECT_NEAR(row_sums[r], d.area[r], 1e-9 * d.area[r]) << r;
  }
}

TEST(ClosedEdges, AContactZoneOnALoopIsTheLoopLessItsLongestOpenStretch) {
  // Ten nodes 1 apart round a loop of length 10.
  Eigen::VectorXd s(10), p = Eigen::VectorXd::Zero(10);
  for (int i = 0; i < 10; ++i) s[i] = i;
  // All round.
  ContactExtent e = contact_extent(s, Eigen::VectorXd::Ones(10), 10.0);
  EXPECT_TRUE(e.any);
  EXPECT_EQ(e.begin, 0.0);
  EXPECT_EQ(e.end, 10.0);
  // Nodes 8, 9, 0, 1 in contact with a flat pressure: the zone runs across the start, from node 8 to node 1.
  p << 1, 1, 0, 0, 0, 0, 0, 0, 1, 1;
  e = contact_extent(s, p, 10.0);
  EXPECT_EQ(e.begin, 8.0);
  EXPECT_EQ(e.end, 1.0);
  // As an open line the same pressures span the whole edge.
  e = contact_extent(s, p);
  EXPECT_EQ(e.begin, 0.0);
  EXPECT_EQ(e.end, 9.0);
  // A square-root profile across the start: p^2 linear, extrapolated to zero beyond its last nodes, round the loop.
  // p^2 = 4 - (x)^2 ... with p^2 falling by 1 per node from node 0 both ways: p^2 = 3 at 0, 2 at +-1, 1 at +-2.
  p.setZero();
  p[0] = std::sqrt(3.0);
  p[1] = p[9] = std::sqrt(2.0);
  p[2] = p[8] = 1.0;
  e = contact_extent(s, p, 10.0);
  EXPECT_NEAR(e.begin, 7.0, 1e-12);  // p^2 = 0 one node beyond node 8
  EXPECT_NEAR(e.end, 3.0, 1e-12);
}
