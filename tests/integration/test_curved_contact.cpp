// Curved contact as exact as flat contact (issue 29, items 3 and 4): the shrink fit of api/examples/shrink_fit.json
// on NON-matching meshes, where the two sides cut the same circle differently. The gap and the normals come from
// the circle (the block's arc edges, the Gmsh file's circles: mortar/edge_curves.hpp), not from the two polygons,
// and where a slave edge meets several master edges, or several slave edges meet at a point, the pairs share one
// dual basis and one row per node (docs/algorithm.md, "Contact geometry on curves", "Where contact edges meet").
//
// Lame (plane strain): p = E' delta / (2 a) (1 - a^2 / b^2) = 109.89, E' = E / (1 - nu^2), uniform round the bore.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "polar_meshes.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;

namespace {

constexpr double kE = 2e5, kNu = 0.3, kA = 500, kB = 1000, kDelta = 0.6667;

double lame() { return kE / (1 - kNu * kNu) * kDelta / (2 * kA) * (1 - kA * kA / (kB * kB)); }

// The pressures of a step's contact nodes (status 0) over all its pairs: each slave node carries its multiplier
// in one pair.
struct Pressures {
  double min = 1e300, max = -1e300;
  double force_averaged = 0;  // the pairs' total normal force over their total weight
  int nodes = 0;
  double worst() const { return std::max(std::abs(min - lame()), std::abs(max - lame())) / lame(); }
};

Pressures pressures(const Step& step) {
  Pressures out;
  double force = 0, weight = 0;
  for (const PairField& pair : step.pairs) {
    force += pair.force;
    for (Eigen::Index i = 0; i < pair.pressure.size(); ++i) {
      if (pair.status[i] != 0) continue;
      ++out.nodes;
      out.min = std::min(out.min, pair.pressure[i]);
      out.max = std::max(out.max, pair.pressure[i]);
      weight += pair.weight[i];
    }
  }
  out.force_averaged = weight > 0 ? force / weight : 0;
  return out;
}

// The quarter model of api/examples/shrink_fit.json on non-matching arcs: the shaft's quarter a block of
// shaft_cells x shaft_cells (its two arc edges "right" and "top" each cut into shaft_cells per 45 degrees), the
// ring's quarter ring_cells per 90 degrees round and ring_cells / 2 across. Two pairs: the ring's bore against
// each of the shaft's arcs (one slave edge, two master edges meeting at 45 degrees), or each of the shaft's arcs
// against the bore (two slave edges meeting there).
json quarter_fit(int shaft_cells, int ring_cells, bool ring_slave) {
  json job = example("shrink_fit.json");
  job["bodies"][0]["mesh"]["block"]["nx"] = shaft_cells;
  job["bodies"][0]["mesh"]["block"]["ny"] = shaft_cells;
  job["bodies"][1]["mesh"]["block"]["nx"] = ring_cells / 2;
  job["bodies"][1]["mesh"]["block"]["ny"] = ring_cells;
  if (!ring_slave)
    job["contacts"] =
        json::array({{{"slave", "shaft.right"}, {"master", "ring.left"}, {"gap", {{"constant", -kDelta}}}},
                     {{"slave", "shaft.top"}, {"master", "ring.left"}, {"gap", {{"constant", -kDelta}}}}});
  return job;
}

// The full 360-degree model of tests/data/shrink_fit_full_gmsh_nonmatching.geo from one of its .msh files: one
// closed contact curve per body, the bore or the rim as the slave.
Problem full_gmsh(const std::string& file, bool ring_slave) {
  json job = json::parse(R"({
    "name": "shrink_fit_full_gmsh_nonmatching", "version": 1, "model": {"plane": "strain"},
    "bodies": [
      {"name": "shaft", "material": {"E": 2e5, "nu": 0.3}, "mesh": {"gmsh": {"file": "", "surface": "shaft"}},
       "boundary": [{"vertex": "centre", "displacement": {"x": 0, "y": 0}},
                    {"vertex": "shaft_east", "displacement": {"y": 0}}]},
      {"name": "ring", "material": {"E": 2e5, "nu": 0.3}, "mesh": {"gmsh": {"file": "", "surface": "ring"}},
       "boundary": [{"vertex": "ring_east", "displacement": {"y": 0}},
                    {"vertex": "ring_west", "displacement": {"y": 0}},
                    {"vertex": "ring_north", "displacement": {"x": 0}}]}
    ],
    "contacts": [{"slave": "ring.bore", "master": "shaft.rim", "gap": {"constant": -0.6667}}]
  })");
  job["bodies"][0]["mesh"]["gmsh"]["file"] = file;
  job["bodies"][1]["mesh"]["gmsh"]["file"] = file;
  if (!ring_slave)
    job["contacts"][0] = {{"slave", "shaft.rim"}, {"master", "ring.bore"}, {"gap", {{"constant", -kDelta}}}};
  job::Limits limits;
  limits.mesh_directory = std::string(CONTACT_SOURCE_DIR) + "/tests/data";
  auto parsed = job::parse(job, limits);
  EXPECT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  return parsed.ok() ? *parsed.problem : Problem{};
}

// Solves and measures, printing the row of the measurements table (docs/algorithm.md).
Pressures measure(const Problem& problem, const std::string& what) {
  const auto start = std::chrono::steady_clock::now();
  const Result r = solve_quietly(problem);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(r.converged) << what << ": " << r.message;
  if (!r.converged) return {};
  const Pressures s = pressures(r.steps.back());
  std::printf(
      "[ measured ] %s: %d contact nodes, min %.3f max %.3f force-averaged %.4f (Lame %.4f; worst node %+.2f %%, "
      "force-averaged %+.3f %%; %.1f s)\n",
      what.c_str(), s.nodes, s.min, s.max, s.force_averaged, lame(), 100 * s.worst(),
      100 * (s.force_averaged / lame() - 1), seconds);
  return s;
}

void expect_lame(const Pressures& s, const std::string& what) {
  const double p = lame();
  EXPECT_GT(s.nodes, 0) << what;
  EXPECT_NEAR(s.min, p, 0.02 * p) << what;
  EXPECT_NEAR(s.max, p, 0.02 * p) << what;
  EXPECT_NEAR(s.force_averaged, p, 0.005 * p) << what;
}

}  // namespace

class CurvedQuarterFit : public ::testing::TestWithParam<bool> {};

TEST_P(CurvedQuarterFit, NonMatchingArcsCarryLamesPressureAtEveryNodeAndConvergeUnderRefinement) {
  // The issue's mesh pairs (shaft cells per 45 degrees / ring cells per 90): 16 / 40 and 32 / 100, then 64 / 160.
  // Measured with the gap between the chords, pair by pair: 0 to 323, 94 to 124 and 69 to 172 with the ring the
  // slave, 66 to 130, 89 to 125 and 98 to 117 with the shaft (force-averaged 5.2 %, 2.2 % and 0.33 % low). Now every
  // node is within 0.1 % of Lame, and the force-averaged error falls at each refinement (+0.05 %, +0.009 %,
  // +0.003 %). The worst node's falls from the first pair to the last (+0.08 % to +0.013 %); from 32 / 100 on it sits
  // at about 1e-4 of Lame, the level of the bodies' own discretisation error, where it need not fall monotonically.
  const bool ring_slave = GetParam();
  double first_worst = 0, previous = 1.0;
  for (const auto& [shaft, ring] : {std::pair{16, 40}, std::pair{32, 100}, std::pair{64, 160}}) {
    const std::string what = "quarter " + std::to_string(shaft) + " / " + std::to_string(ring) +
                             (ring_slave ? ", ring slave" : ", shaft slave");
    const Pressures s = measure(parse_or_fail(quarter_fit(shaft, ring, ring_slave)), what);
    expect_lame(s, what);
    EXPECT_LT(s.worst(), 0.002) << what;
    const double averaged = std::abs(s.force_averaged / lame() - 1);
    EXPECT_LT(averaged, previous) << what << ": the force-averaged error falls as both meshes are refined";
    previous = averaged;
    if (first_worst == 0) first_worst = s.worst();
    if (shaft == 64) EXPECT_LT(s.worst(), 0.5 * first_worst) << what;
  }
}

INSTANTIATE_TEST_SUITE_P(RingOrShaftSlave, CurvedQuarterFit, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "ring_slave" : "shaft_slave"; });

class CurvedFullGmshFit : public ::testing::TestWithParam<bool> {};

TEST_P(CurvedFullGmshFit, NonMatchingClosedCurvesCarryLamesPressureAtEveryNodeAndConvergeUnderRefinement) {
  // 96 arcs round the shaft against 128 round the bore, then 192 against 256 (and a finer interior).
  const bool ring_slave = GetParam();
  double previous = 1.0;
  for (const std::string file : {"shrink_fit_full_gmsh_24_32.msh", "shrink_fit_full_gmsh_48_64.msh"}) {
    const std::string what = "gmsh " + file + (ring_slave ? ", ring slave" : ", shaft slave");
    const Problem problem = full_gmsh(file, ring_slave);
    ASSERT_EQ(problem.bodies.size(), 2u);
    const Pressures s = measure(problem, what);
    expect_lame(s, what);
    EXPECT_LT(s.worst(), previous) << what << ": the worst node's error falls as both meshes are refined";
    previous = s.worst();
  }
}

INSTANTIATE_TEST_SUITE_P(RingOrShaftSlave, CurvedFullGmshFit, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "ring_slave" : "shaft_slave"; });

class CurvedJunction : public ::testing::TestWithParam<bool> {};

TEST_P(CurvedJunction, WhereTheShaftsArcsMeetInsideARingSegmentAUniformPressureStaysUniform) {
  // The quarter fit with 41 ring cells (the shaft's arcs meet at 45 degrees inside a ring segment) and the ring's
  // cells graded towards its bottom (ratios 1.05 to 2), which moves that point along the segment, near its ends too.
  // Pair by pair, the segment across the join got two consistent dual bases on its two partly covered parts (the
  // ring the slave), or the shaft's shared node two half multipliers (the shaft the slave): measured before the
  // pairs were grouped, 0 to 1,609 and 80 to 144 where Lame gives 109.9. Grouped (mortar/pair_group.hpp), the two
  // pairs are one surface with one multiplier per node.
  const bool ring_slave = GetParam();
  for (const double grading : {1.0, 1.05, 1.2, 1.5, 2.0}) {
    json job = quarter_fit(16, 41, ring_slave);
    if (grading != 1.0) job["bodies"][1]["mesh"]["block"]["grading"] = {{"bottom", grading}};
    const std::string what =
        "junction, ring graded " + std::to_string(grading) + (ring_slave ? ", ring slave" : ", shaft slave");
    const Problem problem = parse_or_fail(job);
    const Result r = solve_quietly(problem);
    ASSERT_TRUE(r.converged) << what << ": " << r.message;
    const Pressures s = pressures(r.steps.back());
    expect_lame(s, what);
    // Each slave node carries its multiplier in one pair only.
    std::map<int, int> pairs_of_node;
    for (const PairField& pair : r.steps.back().pairs)
      for (Eigen::Index i = 0; i < pair.pressure.size(); ++i)
        if (pair.status[i] == 0) ++pairs_of_node[pair.node[i]];
    for (const auto& [node, count] : pairs_of_node) EXPECT_EQ(count, 1) << what << ", slave node " << node;
    std::printf("[ measured ] %s: min %.3f max %.3f force-averaged %.4f (Lame %.4f)\n", what.c_str(), s.min, s.max,
                s.force_averaged, lame());
  }
}

INSTANTIATE_TEST_SUITE_P(RingOrShaftSlave, CurvedJunction, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "ring_slave" : "shaft_slave"; });

TEST(CurvedGroups, AClosedCurveCutIntoFourPairsIsTheClosedCurvesOnePairAgain) {
  // The full shrink fit of test_closed_curves.cpp on matching polar meshes (64 nodes round), the shaft's rim cut
  // into its four quarters, each its own pair with the ring's bore: four slave edges chained into a loop against one
  // closed master (the rim the slave), or one closed slave against four master edges (the bore the slave). Grouped
  // (mortar/pair_group.hpp) they are the closed pair's discrete problem again: the same pressure at every node, to
  // the solver's tolerance, each node's multiplier in one of the four pairs.
  const FullShrinkFit fit;
  for (const bool ring_slave : {true, false}) {
    const Result whole = solve_quietly(fit.problem(64, 64, ring_slave));
    ASSERT_TRUE(whole.converged) << whole.message;
    Problem quarters = fit.problem(64, 64, ring_slave);
    auto& rim = quarters.bodies[0].mesh.edge_sets;
    const auto sides = rim.at("rim");
    const ContactPair one = quarters.contacts[0];
    quarters.contacts.clear();
    for (int q = 0; q < 4; ++q) {
      const std::string name = "rim" + std::to_string(q);
      rim[name].assign(sides.begin() + 16 * q, sides.begin() + 16 * (q + 1));
      ContactPair c = one;
      (ring_slave ? c.master_edge : c.slave_edge) = name;
      c.name = one.name + "." + name;
      quarters.contacts.push_back(c);
    }
    const Result cut = solve_quietly(quarters);
    ASSERT_TRUE(cut.converged) << cut.message;
    std::map<int, double> expected, got;
    std::map<int, int> pairs_of_node;
    const PairField& single = whole.steps.back().pairs.at(0);
    for (Eigen::Index i = 0; i < single.pressure.size(); ++i)
      if (single.status[i] == 0) expected[single.node[i]] = single.pressure[i];
    for (const PairField& pair : cut.steps.back().pairs)
      for (Eigen::Index i = 0; i < pair.pressure.size(); ++i)
        if (pair.status[i] == 0) {
          got[pair.node[i]] = pair.pressure[i];
          ++pairs_of_node[pair.node[i]];
        }
    ASSERT_EQ(got.size(), expected.size()) << (ring_slave ? "ring" : "shaft") << " slave";
    for (const auto& [node, p] : expected) {
      EXPECT_NEAR(got[node], p, 1e-6 * p) << "node " << node;
      EXPECT_EQ(pairs_of_node[node], 1) << "node " << node;
    }
  }
}

TEST(PairGroupTables, EveryNodeOfAGroupedPairCarriesLamesPressureOrTheCarryingPairsValue) {
  // The quarter fit with the ring's bore (100 cells per 90 degrees) the slave of both shaft arcs (32 cells per 45):
  // each pair's table lists all 101 bore nodes. The half opposite the other pair's arc is that pair's: status 5,
  // with its values. They were listed with status 4 or 5 and pressure 0 (48 of 101 in each pair) while the contact
  // itself was exact. Lame's pressure everywhere, since the fit is uniform.
  const Result r = solve_quietly(parse_or_fail(quarter_fit(32, 100, true)));
  ASSERT_TRUE(r.converged) << r.message;
  const auto& pairs = r.steps.back().pairs;
  ASSERT_EQ(pairs.size(), 2u);
  const double p = lame();
  std::map<int, double> carried;  // slave node -> the pressure of the pair that carries it
  int own = 0, elsewhere = 0;
  for (const PairField& pair : pairs)
    for (Eigen::Index i = 0; i < pair.status.size(); ++i)
      if (pair.status[i] == 0 || pair.status[i] == 4) {
        EXPECT_NEAR(pair.pressure[i], p, 0.02 * p) << pair.name << " node " << pair.node[i];
        carried[pair.node[i]] = pair.pressure[i];
        ++own;
      }
  for (const PairField& pair : pairs)
    for (Eigen::Index i = 0; i < pair.status.size(); ++i)
      if (pair.status[i] == 5) {
        ++elsewhere;
        ASSERT_TRUE(carried.count(pair.node[i])) << pair.name << " node " << pair.node[i] << " is carried by no pair";
        EXPECT_EQ(pair.pressure[i], carried[pair.node[i]]) << pair.name << " node " << pair.node[i];
        EXPECT_EQ(pair.active[i], 1) << pair.name << " node " << pair.node[i];
        EXPECT_TRUE(std::isfinite(pair.normal_gap[i])) << pair.name << " node " << pair.node[i];
      }
  EXPECT_EQ(static_cast<int>(carried.size()), 101) << "every bore node carried by a pair";
  EXPECT_GT(elsewhere, 90) << "about half of each pair's nodes are the other's";
  EXPECT_GE(own, 101);
  // The pairs' forces add their own rows only: a node is counted once.
  EXPECT_NEAR(pairs[0].force + pairs[1].force, p * 0.5 * 3.14159265358979323846 * 500.0, 0.005 * p * 785.4);
}
