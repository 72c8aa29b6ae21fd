// The contact geometry of curved edges (mortar/edge_curves.hpp), the arcs fitted to curves known only by their
// nodes (mesh/curve_fit.hpp) and the groups of pairs that share a contact surface (mortar/pair_group.hpp): unit
// checks against the curves' own equations.
#include "mesh/curve_fit.hpp"
#include "mesh/gmsh.hpp"
#include "mortar/edge_curves.hpp"
#include "mortar/pair_group.hpp"
#include "mortar/segments.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

using namespace contact;
using namespace contact::mortar;
using namespace contact::testing;

namespace {

mesh::Curve arc(const Eigen::Vector2d& centre, double radius) {
  mesh::Curve c;
  c.kind = mesh::Curve::Kind::arc;
  c.center = centre;
  c.radius = radius;
  return c;
}

}  // namespace

TEST(EdgeCurves, AStraightSegmentIsItsOwnChordBitForBit) {
  // No curve, or a line: the chord's point and the chord's normal exactly (the flat cases' arithmetic).
  const std::vector<Eigen::Vector2d> points = {{0.1, 0.3}, {0.7, 0.9}, {1.9, 1.1}};
  mesh::Curve line;
  const EdgeCurves e(points, {std::nullopt, line});
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_FALSE(e.curved(k));
    for (double xi : {0.0, 0.2113248654051871, 0.5, 1.0}) {
      const EdgeCurves::Frame f = e.at(k, xi);
      const Eigen::Vector2d x = points[k] + xi * (points[k + 1] - points[k]);
      EXPECT_EQ(f.point, x);
      EXPECT_EQ(f.normal, outward_normal(points[k], points[k + 1]));
    }
  }
  // The hit on a chord: x + t n on the chord's line.
  const Eigen::Vector2d x(0.5, 0.2), n = Eigen::Vector2d(0.3, 1.0).normalized();
  const double t = *e.hit(0, x, n);
  EXPECT_NEAR(outward_normal(points[0], points[1]).dot(x + t * n - points[0]), 0.0, 1e-15);  // on the chord's line
}

TEST(EdgeCurves, ChordPointsOfAnArcStandForTheArcsPointsAndTheGapBetweenConcentricArcsIsTheirRadii) {
  // A shaft's rim (convex, counter-clockwise) of radius 500 cut into 7 chords, and a bore (concave: the ring's
  // boundary runs clockwise round the hole) of radius 500.5 cut into 11: every chord point's image lies on its
  // circle with the radial normal pointing out of its body, and from the rim along that normal the bore is 0.5 away
  // wherever the chords are, however differently the two sides cut the circle.
  const Eigen::Vector2d c(3.0, -2.0);
  const double a = 500.0, b = 500.5, pi = 3.14159265358979323846;
  auto points = [&](double r, int n, bool ccw) {
    std::vector<Eigen::Vector2d> p;
    for (int j = 0; j <= n; ++j) {
      const double t = 0.5 * pi * (ccw ? j : n - j) / n;
      p.push_back(c + r * Eigen::Vector2d(std::cos(t), std::sin(t)));
    }
    return p;
  };
  const EdgeCurves rim(points(a, 7, true), std::vector<std::optional<mesh::Curve>>(7, arc(c, a)));
  const EdgeCurves bore(points(b, 11, false), std::vector<std::optional<mesh::Curve>>(11, arc(c, b)));
  for (size_t k = 0; k < 7; ++k)
    for (double xi : {0.0, 0.1127016653792583, 0.5, 0.8872983346207417, 1.0}) {
      const EdgeCurves::Frame f = rim.at(k, xi);
      EXPECT_NEAR((f.point - c).norm(), a, 1e-12 * a);
      EXPECT_NEAR(f.normal.dot((f.point - c) / a), 1.0, 1e-15);  // out of the shaft
      size_t hits = 0;
      for (size_t j = 0; j < 11; ++j) {
        const auto t = bore.hit(j, f.point, f.normal);
        ASSERT_TRUE(t.has_value());
        EXPECT_NEAR(*t, b - a, 1e-9);
        const double eta = bore.chord_parameter(j, f.point + *t * f.normal);
        hits += eta >= -1e-9 && eta <= 1 + 1e-9 ? 1 : 0;
      }
      EXPECT_GE(hits, 1u);  // on some segment's stretch
      const EdgeCurves::Frame g = bore.at(k, xi);
      EXPECT_NEAR(g.normal.dot((g.point - c) / b), -1.0, 1e-15);  // out of the ring: towards the centre
    }
}

TEST(EdgeCurves, TheGapToAParabolaIsTheRootOfTheLinesQuadratic) {
  // y = 0.5 x^2 - x + 2 over [0, 2], the top of a body below it (so run from x = 2 to x = 0, the outward normal
  // up); the line from (1, 0) straight up meets the parabola at y = 1.5.
  mesh::Curve p;
  p.kind = mesh::Curve::Kind::parabola;
  p.a = 0.5;
  p.b = -1.0;
  p.c = 2.0;
  const EdgeCurves e({{2.0, 2.0}, {0.0, 2.0}}, {p});
  EXPECT_NEAR(*e.hit(0, Eigen::Vector2d(1.0, 0.0), Eigen::Vector2d(0.0, 1.0)), 1.5, 1e-15);
  const EdgeCurves::Frame f = e.at(0, 0.75);  // x = 0.5: y = 1.625, slope -0.5, the normal along (0.5, 1)
  EXPECT_NEAR(f.point.x(), 0.5, 1e-15);
  EXPECT_NEAR(f.point.y(), 1.625, 1e-15);
  EXPECT_NEAR(f.normal.dot(Eigen::Vector2d(0.5, 1.0).normalized()), 1.0, 1e-15);
}

TEST(PairGroups, TheQuarterFitsPairsShareOneSurfaceAndACornerDoesNot) {
  // api/examples/shrink_fit.json: the bore against the shaft's two arcs, which chain at 45 degrees (the shaft's
  // "right" ends where its "top" begins, tangentially): one group, the master chain right then top, 33 nodes.
  const Problem fit = parse_or_fail(example("shrink_fit.json"));
  for (int p : {0, 1}) {
    const PairGroup g = pair_group(fit, p);
    EXPECT_EQ(g.pairs, (std::vector<int>{0, 1}));
    EXPECT_EQ(g.slave.edges, (std::vector<std::string>{"left"}));
    EXPECT_EQ(g.master.edges, (std::vector<std::string>{"right", "top"}));
    EXPECT_EQ(g.master.start, (std::vector<size_t>{0, 16}));
    EXPECT_EQ(g.master.nodes.size(), 33u);
    EXPECT_FALSE(g.master.closed);
    EXPECT_EQ(g.pair_of(0, 0), 0);
    EXPECT_EQ(g.pair_of(0, 1), 1);
    EXPECT_EQ(g.master.edge_of_segment(15), 0u);
    EXPECT_EQ(g.master.edge_of_segment(16), 1u);
  }
  // The shaft's bottom (a radius) turns into its right arc at (500, 0) through a right angle: a corner, where each
  // edge keeps its own multiplier and normal, so the two pairs stay apart.
  // (Built in code: the job reader refuses shaft.bottom -> ring.left, whose edges never face each other.)
  Problem cornered = fit;
  for (auto& c : cornered.contacts) {
    c.slave_body = 0;  // shaft
    c.master_body = 1;  // ring
    c.master_edge = "left";
  }
  cornered.contacts[0].slave_edge = "bottom";
  cornered.contacts[1].slave_edge = "right";
  EXPECT_EQ(pair_group(cornered, 0).pairs, (std::vector<int>{0}));
  EXPECT_EQ(pair_group(cornered, 1).pairs, (std::vector<int>{1}));
  // The stack's pairs are between different bodies: each alone.
  const Problem stack = parse_or_fail(example("stack3.json"));
  for (int p = 0; p < static_cast<int>(stack.contacts.size()); ++p)
    EXPECT_EQ(pair_group(stack, p).pairs, (std::vector<int>{p}));
}

TEST(FittedArcs, OnAnEllipseTheyStrayFromTheCurveAsHCubedWhereTheChordsStrayAsHSquared) {
  // The quarter ellipse x = 3 cos t, y = 2 sin t (an open chain) and the whole one (closed), N sides at equal steps
  // of t: the largest distance from the ellipse of the points of each side's fitted arc (mesh/curve_fit.hpp) and of
  // its chord, sampled at 9 points per side, the distance taken as |F| / |grad F| for F = x^2 / 9 + y^2 / 4 - 1
  // (exact to second order in the distance). The orders between N and 2N: the chord's 2, the fitted arc's 3 (the
  // printed measurements are those of docs/algorithm.md).
  const double pi = 3.14159265358979323846;
  auto distance = [](const mesh::Point& p) {
    const double F = p.x() * p.x() / 9 + p.y() * p.y() / 4 - 1;
    return std::abs(F) / mesh::Point(2 * p.x() / 9, p.y() / 2).norm();
  };
  for (const bool closed : {false, true}) {
    double previous_fit = 0, previous_chord = 0;
    for (int n : {16, 32, 64, 128}) {
      std::vector<mesh::Point> nodes;
      const double span = closed ? 2 * pi : 0.5 * pi;
      for (int j = 0; j < (closed ? n : n + 1); ++j)
        nodes.emplace_back(3 * std::cos(span * j / n), 2 * std::sin(span * j / n));
      const auto arcs = mesh::fitted_arcs(nodes, closed);
      ASSERT_EQ(arcs.size(), static_cast<size_t>(n));
      double fit = 0, chord = 0;
      for (int k = 0; k < n; ++k) {
        const mesh::Point a = nodes[static_cast<size_t>(k)], b = nodes[static_cast<size_t>((k + 1) % nodes.size())];
        ASSERT_TRUE(arcs[static_cast<size_t>(k)].has_value()) << k;
        for (int s = 1; s < 10; ++s) {
          fit = std::max(fit, distance(arcs[static_cast<size_t>(k)]->between(a, b, s / 10.0)));
          chord = std::max(chord, distance(a + s / 10.0 * (b - a)));
        }
      }
      if (previous_fit > 0) {
        const double fit_order = std::log2(previous_fit / fit), chord_order = std::log2(previous_chord / chord);
        std::printf(
            "[ measured ] %s ellipse, %d -> %d sides: fitted arcs %.3g (order %.2f), chords %.3g (order %.2f)\n",
            closed ? "closed" : "quarter", n / 2, n, fit, fit_order, chord, chord_order);
        EXPECT_NEAR(chord_order, 2.0, 0.1);
        EXPECT_GT(fit_order, 2.8);
      }
      EXPECT_LT(fit, chord / 10) << n;
      previous_fit = fit;
      previous_chord = chord;
    }
  }
}

TEST(FittedArcs, AGmshEllipseGetsThemOnEverySideAndRefinementPutsItsNewNodesOnThem) {
  // tests/data/half_ellipse_gmsh.msh: the half ellipse x^2 / 9 + y^2 / 4 <= 1, y >= 0, its curved side two Gmsh
  // Ellipse curves of 12 sides each. Every side of the rim gets a fitted arc through its two nodes, the straight base
  // none; each arc's midpoint lies nearer the ellipse than its chord's, the farthest 10 times nearer than the
  // farthest chord's (the two Ellipse curves are fitted each on its own, so their ends use one-sided triples), and a
  // uniform refinement puts the rim's new nodes on the arcs.
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/tests/data/half_ellipse_gmsh.msh");
  std::stringstream text;
  text << in.rdbuf();
  auto s = mesh::gmsh::surface(mesh::gmsh::parse(text.str(), 1'000'000), "plate");
  ASSERT_TRUE(s.errors.empty()) << s.errors[0];
  auto distance = [](const mesh::Point& p) {
    const double F = p.x() * p.x() / 9 + p.y() * p.y() / 4 - 1;
    return std::abs(F) / mesh::Point(2 * p.x() / 9, p.y() / 2).norm();
  };
  const std::vector<int> rim = s.mesh.edge_set_nodes("rim");
  ASSERT_EQ(rim.size(), 25u);
  EXPECT_EQ(s.mesh.side_curves.size(), 24u);  // the rim's sides, none of the base's
  double arc_worst = 0, chord_worst = 0;
  for (size_t k = 0; k + 1 < rim.size(); ++k) {
    const mesh::Point a = s.mesh.nodes[static_cast<size_t>(rim[k])], b = s.mesh.nodes[static_cast<size_t>(rim[k + 1])];
    const auto c = s.mesh.side_curves.find(std::minmax(rim[k], rim[k + 1]));
    ASSERT_NE(c, s.mesh.side_curves.end()) << k;
    EXPECT_EQ(c->second.kind, mesh::Curve::Kind::arc);
    for (const mesh::Point& p : {a, b}) EXPECT_NEAR((p - c->second.center).norm(), c->second.radius, 1e-9);
    const double on_arc = distance(c->second.between(a, b, 0.5)), on_chord = distance(0.5 * (a + b));
    EXPECT_LT(on_arc, on_chord) << k;
    arc_worst = std::max(arc_worst, on_arc);
    chord_worst = std::max(chord_worst, on_chord);
  }
  EXPECT_LT(arc_worst, 0.1 * chord_worst);
  std::printf("[ measured ] Gmsh ellipse, 24 sides: midpoints at most %.2g from it on the arcs, %.2g on the chords\n",
              arc_worst, chord_worst);
  mesh::refine_uniform(s.mesh);
  const std::vector<int> refined = s.mesh.edge_set_nodes("rim");
  ASSERT_EQ(refined.size(), 49u);
  for (int n : refined) EXPECT_LE(distance(s.mesh.nodes[static_cast<size_t>(n)]), arc_worst + 1e-12) << n;
}

TEST(FittedArcs, CornersSplitAChainSoNoArcRoundsACornerOffAndStraightPiecesKeepTheirChords) {
  // An L of straight sides (an explicit edge round two sides of a punch): one corner, no arc anywhere, so a flat
  // edge computes exactly what it did.
  const std::vector<mesh::Point> l = {{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}};
  EXPECT_EQ(mesh::chain_corners(l, false), (std::vector<bool>{false, false, true, false, false}));
  for (const auto& a : mesh::fitted_arcs(l, false)) EXPECT_FALSE(a.has_value());
  // A quarter circle of radius 2 in 8 sides (11.25 degrees each) from (2, 0) to (0, 2), then straight down the y
  // axis to the centre: the corner at (0, 2) turns through 84.4 degrees. The arc's sides get the circle itself
  // (every triple on it, the piece's ends one-sided), the straight ones none.
  const double pi = 3.14159265358979323846;
  std::vector<mesh::Point> d;
  for (int j = 0; j <= 8; ++j) d.emplace_back(2 * std::cos(0.5 * pi * j / 8), 2 * std::sin(0.5 * pi * j / 8));
  d.emplace_back(0, 1);
  d.emplace_back(0, 0);
  const auto corners = mesh::chain_corners(d, false);
  for (size_t i = 0; i < d.size(); ++i) EXPECT_EQ(corners[i], i == 8) << i;
  const auto arcs = mesh::fitted_arcs(d, false);
  ASSERT_EQ(arcs.size(), 10u);
  for (size_t k = 0; k < 8; ++k) {
    ASSERT_TRUE(arcs[k].has_value()) << k;
    EXPECT_NEAR(arcs[k]->radius, 2.0, 1e-12) << k;
    EXPECT_NEAR(arcs[k]->center.norm(), 0.0, 1e-12) << k;
  }
  EXPECT_FALSE(arcs[8].has_value());
  EXPECT_FALSE(arcs[9].has_value());
  // Closed: the same piece closed back to (2, 0) has corners at (0, 2), the centre... (0, 0) turns 90 degrees
  // too, and (2, 0) 95.6: three corners, the arc's sides fitted as before.
  const auto closed = mesh::fitted_arcs(d, true);
  ASSERT_EQ(closed.size(), 11u);
  for (size_t k = 0; k < 8; ++k) ASSERT_TRUE(closed[k].has_value() && std::abs(closed[k]->radius - 2) < 1e-12) << k;
  for (size_t k = 8; k < 11; ++k) EXPECT_FALSE(closed[k].has_value()) << k;
}

TEST(FittedArcs, ASmoothCurveHasNoCornersEvenCoarseOrGradedButAKinkInItIsOne) {
  const double pi = 3.14159265358979323846;
  // A 12-gon (30 degrees at every node) and a circle graded by 1.5 from side to side: no corner.
  std::vector<mesh::Point> twelve, graded;
  for (int j = 0; j < 12; ++j) twelve.emplace_back(std::cos(pi * j / 6), std::sin(pi * j / 6));
  double t = 0, step = 0.02;
  for (int j = 0; j < 8; ++j, t += step, step *= 1.5) graded.emplace_back(std::cos(t), std::sin(t));
  for (bool c : mesh::chain_corners(twelve, true)) EXPECT_FALSE(c);
  for (bool c : mesh::chain_corners(graded, false)) EXPECT_FALSE(c);
  // Two straight lines meeting at 10 degrees, and the same kink in the middle of a circle's chain (the circle
  // turning 2 degrees per node): each a corner.
  const std::vector<mesh::Point> kink = {{-2, 0}, {-1, 0}, {0, 0}, {std::cos(pi / 18), std::sin(pi / 18)},
                                         {2 * std::cos(pi / 18), 2 * std::sin(pi / 18)}};
  EXPECT_EQ(mesh::chain_corners(kink, false), (std::vector<bool>{false, false, true, false, false}));
  std::vector<mesh::Point> bent;
  double angle = 0;
  mesh::Point x(0, 0);
  for (int j = 0; j < 9; ++j) {
    bent.push_back(x);
    angle += (j == 4 ? 12.0 : 2.0) * pi / 180;
    x += mesh::Point(std::cos(angle), std::sin(angle));
  }
  const auto corners = mesh::chain_corners(bent, false);
  for (size_t i = 0; i < bent.size(); ++i) EXPECT_EQ(corners[i], i == 4) << i;
}
