// Coulomb and Tresca friction (docs/algorithm.md, "Friction"). Every expected number comes from mechanics or an
// independent computation: Cattaneo-Mindlin's partial slip, the Tresca bound times the contact length, equilibrium,
// the frictionless solution at mu = 0, one merged body for a bond that cannot slip, and the monolithic reference
// solving the same discrete problem in one system.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "adaptive_support.hpp"
#include "cattaneo_mindlin.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;  // the shared helpers (support.hpp)

namespace {

const PairField& pair_of(const Step& s, const std::string& name) {
  for (const auto& p : s.pairs)
    if (p.name == name) return p;
  throw std::runtime_error("no pair " + name);
}

double relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  const double scale = std::max(a.norm(), b.norm());
  return scale > 0 ? (a - b).norm() / scale : 0.0;
}

}  // namespace

namespace {

// Cattaneo-Mindlin by the given interface solver ("direct" or "iterative"): the stick zone's half-width c and the
// tangential traction against the theory, equilibrium to 1e-8, Coulomb at every node.
void check_cattaneo_mindlin(const std::string& interface_solver) {
  const double mu = 0.3;
  auto job_of = [&](const std::vector<double>& Q) {
    json job = cattaneo_job(Q);
    job["solver"]["interface"] = {{"solver", interface_solver}};
    return job;
  };
  SCOPED_TRACE("interface solver " + interface_solver);
  // Coulomb to rounding by the direct solver; by the iterative one to its outer iteration's accuracy (its bounds
  // are the last outer iterate's mu z).
  const double tolerance = interface_solver == "direct" ? 1e-9 : 1e-6;
  // The normal force the held top gives (no tangential load yet), to choose the tangential loads.
  const Result first = run(job_of({0.0}));
  ASSERT_TRUE(first.converged) << first.message;
  const double P = pair_of(first.steps.back(), "block.top-cylinder.bottom").force;
  ASSERT_GT(P, 0);
  const std::vector<double> ratios = {0.25, 0.5, 0.75};
  std::vector<double> Q = {0.0};
  for (double r : ratios) Q.push_back(r * mu * P);
  const Result result = run(job_of(Q));
  ASSERT_TRUE(result.converged) << result.message;
  ASSERT_EQ(result.steps.size(), 4u);
  for (size_t k = 1; k < 4; ++k) {
    const PairField& p = pair_of(result.steps[k], "block.top-cylinder.bottom");
    // Equilibrium of the cylinder along x: the flat slave's tangential tractions carry Q (the traction on the
    // block points along +x, its tangent along -x).
    const double carried = -p.weight.dot(p.tangential_traction);
    EXPECT_NEAR(carried, Q[k], 1e-8 * Q[k]) << "step " << k;
    EXPECT_NEAR(p.tangential_force, -Q[k], 1e-8 * Q[k]);
    // Cattaneo-Mindlin with this step's normal force (the held top lets it change by a per cent).
    const MindlinFit fit = mindlin_fit(p, Q[k]);
    EXPECT_NEAR(fit.c_over_a, fit.theory, 0.03) << "Q / (mu P) = " << fit.ratio;
    // Issue 21's bound on its measure, the nodes' root sum of squares; in L2 (cattaneo_mindlin.hpp) the same within
    // 5 % where the slip zone spans many nodes, and 6.4 % at Q / (mu P) = 0.25, where the slip annulus a - c =
    // 0.13 a spans 3.5 nodes (h = 0.046) and the profile falls steeply at both of its ends.
    EXPECT_LT(fit.nodal_traction_error, 0.05) << "Q / (mu P) = " << fit.ratio;
    EXPECT_LT(fit.traction_error, fit.ratio < 0.3 ? 0.07 : 0.05) << "Q / (mu P) = " << fit.ratio;
    // Where a node slips its traction is on the bound.
    for (Eigen::Index j = 0; j < p.position.rows(); ++j)
      if (p.pressure[j] > 0) EXPECT_LE(std::abs(p.tangential_traction[j]), mu * p.pressure[j] * (1 + tolerance));
  }
}

}  // namespace

TEST(Friction, CattaneoMindlinStickZoneAndTractionFollowTheTheory) { check_cattaneo_mindlin("direct"); }

TEST(Friction, CattaneoMindlinAdaptsFromACoarseMeshAndEndsOnTheTheory) {
  // Issue 30, item 3: friction with adaptivity. The load path (press, then Q = half of what friction holds) is
  // solved on each mesh from rest (friction depends on the path: its history is never moved between meshes), the
  // indicators take the whole contact traction as the bodies' Neumann data. From 20 x 4 uniform cells per body.
  const double Q = 0.5 * 0.3 * 2194.0;  // P is 2194 to 0.1 % on fine meshes (the held top sets it)
  json job = cattaneo_mesh(20, 4, false, Q);
  // The adaptivity defaults (issue 50): the goal-oriented marking refines for the pressure's error, the stick-slip
  // points included, and weighs the stress singularities of the cylinder's point loads and the block's held corner
  // by how much they move the contact (little); the run stops where the answer settled. (Under the indicator's
  // marking, the defaults before, a grading of 0.5 kept the refinement from those corners; under the goal marking
  // it stops the run short: the cylinder's top is held, so the force needs the far field, which the grading keeps
  // coarse: docs/job-format.md, "Grading".)
  job["adaptivity"] = json::object();
  job["output"] = {{"steps", "all"}};
  struct Estimates : Observer {
    std::vector<double> of_step;
    void on_adaptive_step(const AdaptiveStepReport& report) override { of_step.push_back(report.pressure_estimate); }
  } estimates;
  CancelToken cancel;
  const Result r = solve(parse_or_fail(job), estimates, cancel);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_GE(r.steps.size(), 4u);
  ASSERT_EQ(estimates.of_step.size(), r.steps.size());
  long first_meeting = 0;
  for (size_t k = 0; k < r.steps.size(); ++k) {
    const Step& s = r.steps[k];
    const PairField& pair = pair_of(s, "block.top-cylinder.bottom");
    const MindlinFit fit = mindlin_fit(pair, Q);
    const long dofs = unknowns(r, s.iteration);
    // The pressure estimate (issue 30, item 2) against the pressure's true error: Hertz's at the step's force
    // (the bodies are 25 half-widths deep: their departure from half-spaces is far below these errors).
    const double truth = hertz_pressure_error(pair), effectivity = estimates.of_step[k] / truth;
    std::printf(
        "  step %d: %ld unknowns, Q / (mu P) %.3f, c / a %.4f (theory %.4f), traction error %.3f (at the "
        "nodes %.3f), pressure error %.3f %%, estimate %.3f %% (effectivity %.2f)\n",
        s.index, dofs, fit.ratio, fit.c_over_a, fit.theory, fit.traction_error, fit.nodal_traction_error, 100 * truth,
        100 * estimates.of_step[k], effectivity);
    // Calibrated: within a factor of 3 either way (the paper's test and two cylinders measure 0.9 to 2.1;
    // docs/algorithm.md, "The pressure estimate") wherever the contact has nodes enough to be resolved at all
    // (6 in contact: at 3 the profile is three values and its error mostly the zone it cannot draw).
    if ((pair.pressure.array() > 0).count() >= 6) {
      EXPECT_GT(effectivity, 1.0 / 3) << "step " << k;
      EXPECT_LT(effectivity, 3.0) << "step " << k;
    }
    if (!first_meeting && std::abs(fit.c_over_a - fit.theory) <= 0.03 && fit.traction_error < 0.05)
      first_meeting = dofs;
  }
  // The last step, what the user receives: Cattaneo-Mindlin, Coulomb at every node, Q carried.
  const PairField& p = pair_of(r.steps.back(), "block.top-cylinder.bottom");
  const MindlinFit fit = mindlin_fit(p, Q);
  EXPECT_NEAR(fit.ratio, 0.5, 0.01);
  EXPECT_NEAR(fit.c_over_a, fit.theory, 0.03);
  EXPECT_LT(fit.traction_error, 0.05);
  EXPECT_NEAR(-p.weight.dot(p.tangential_traction), Q, 1e-8 * Q);
  for (Eigen::Index j = 0; j < p.position.rows(); ++j)
    if (p.pressure[j] > 0) EXPECT_LE(std::abs(p.tangential_traction[j]), 0.3 * p.pressure[j] * (1 + 1e-9));
  // Against meshes graded towards the contact (cattaneo_job's grading 60 in both bodies), the same two tests with
  // the traction in L2: 400 x 12 7.7 %, 500 x 15 7.6 %, 560 x 17 6.8 %, 650 x 20 6.0 %, 800 x 24 5.2 % miss it, and
  // 1000 x 30 (4.1 %, c / a 0.016 off) meets both. The adaptive run meets both with at most a tenth of its
  // unknowns (measured 31x; docs/algorithm.md, "Adaptivity with friction"). By the nodes' values alone, which
  // flatter a coarse mesh whose nodes miss the steep fall inside c, 400 x 12 would meet (2.1 %) and the ratio
  // would be 5.1x.
  const Result coarse = run(cattaneo_mesh(800, 24, true, Q)), graded = run(cattaneo_mesh(1000, 30, true, Q));
  ASSERT_TRUE(coarse.converged) << coarse.message;
  ASSERT_TRUE(graded.converged) << graded.message;
  const MindlinFit coarse_fit = mindlin_fit(pair_of(coarse.steps.back(), "block.top-cylinder.bottom"), Q);
  const MindlinFit graded_fit = mindlin_fit(pair_of(graded.steps.back(), "block.top-cylinder.bottom"), Q);
  EXPECT_TRUE(std::abs(coarse_fit.c_over_a - coarse_fit.theory) > 0.03 || coarse_fit.traction_error >= 0.05)
      << coarse_fit.traction_error;
  EXPECT_LE(std::abs(graded_fit.c_over_a - graded_fit.theory), 0.03);
  EXPECT_LT(graded_fit.traction_error, 0.05);
  const long graded_dofs = unknowns(graded, graded.iterations);
  std::printf("  adaptive meets both at %ld unknowns; graded 1000 x 30: %ld (ratio %.1f)\n", first_meeting, graded_dofs,
              static_cast<double>(graded_dofs) / static_cast<double>(first_meeting));
  ASSERT_GT(first_meeting, 0);
  EXPECT_LE(10 * first_meeting, graded_dofs);
}

TEST(Friction, CattaneoMindlinWithATargetRefinesTheStickSlipPointsAndEndsOnTheTheory) {
  // Issue 30, item 3: marking that serves the stick-slip boundary. With a target the refinement follows the
  // shares of the estimate (docs/algorithm.md, "Refinement for the pressure's target"); with friction the estimate
  // has a term for the stick-slip points: the slack (mu p - |q|) rises from them into the stick zone like a
  // square root (Mindlin: mu p0 (c / a) sqrt(1 - x^2 / c^2)), which the piecewise-linear traction misses as the
  // pressure misses its edges. From the coarse 20 x 4 mesh with a target of 0.5 %.
  const double Q = 0.5 * 0.3 * 2194.0;
  json job = cattaneo_mesh(20, 4, false, Q);
  job["adaptivity"] = {{"target_error", 0.005}};
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NE(r.message.find("target met after"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("stick-slip points"), std::string::npos) << r.message;
  // The last step is on the theory (measured: c / a 0.0017 off, traction 3.8 % in L2, 12,584 unknowns).
  const PairField& p = pair_of(r.steps.back(), "block.top-cylinder.bottom");
  const MindlinFit fit = mindlin_fit(p, Q);
  std::printf("  %ld unknowns: c / a %.4f (theory %.4f), traction error %.4f\n", unknowns(r, r.steps.back().iteration),
              fit.c_over_a, fit.theory, fit.traction_error);
  EXPECT_NEAR(fit.c_over_a, fit.theory, 0.03);
  EXPECT_LT(fit.traction_error, 0.05);
  // The slave's segments at the stick-slip points are finer than in the middle of the stick zone, by 4x (by 2x
  // without the stick-slip term, where only the pressure's shares steered the refinement there).
  std::vector<std::pair<double, int>> nodes;  // (x, sticks)
  for (Eigen::Index j = 0; j < p.position.rows(); ++j)
    nodes.emplace_back(p.position(j, 0), p.stick[static_cast<size_t>(j)]);
  std::sort(nodes.begin(), nodes.end());
  size_t last_stick = 0, centre = 0;
  for (size_t j = 0; j < nodes.size(); ++j) {
    if (nodes[j].second) last_stick = j;
    if (std::abs(nodes[j].first) < std::abs(nodes[centre].first)) centre = j;
  }
  ASSERT_GT(last_stick, centre);
  ASSERT_LT(last_stick + 1, nodes.size());
  const double h_stick_slip = nodes[last_stick + 1].first - nodes[last_stick].first;
  const double h_centre = nodes[centre + 1].first - nodes[centre].first;
  std::printf("  segment at the stick-slip point %.5f, at the centre %.5f\n", h_stick_slip, h_centre);
  EXPECT_LT(h_stick_slip, 0.3 * h_centre);
}

TEST(Friction, CattaneoMindlinByTheIterativeSolverFollowsTheTheoryToo) { check_cattaneo_mindlin("iterative"); }

namespace {

// A block (1 x 0.5) on a foundation (2 x 0.5), non-matching meshes, Tresca friction g = 5 along the contact; the
// block's top is moved sideways by up to 0.05 (a shear stress of about G 0.05 / 0.5 = 38 if it stuck) and pressed.
json tresca_job() {
  return json::parse(R"({
    "name": "tresca",
    "bodies": [
      {"name": "ground", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[-1, -0.5], [1, -0.5], [1, 0], [-1, 0]], "nx": 20, "ny": 5}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
      {"name": "block", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[-0.5, 0], [0.5, 0], [0.5, 0.5], [-0.5, 0.5]], "nx": 7, "ny": 4}},
       "boundary": [{"edge": "top", "displacement": {"x": 0.05, "y": -0.005}}]}
    ],
    "contacts": [{"name": "c", "slave": "block.bottom", "master": "ground.top", "friction": {"bound": 5}}],
    "loading": {"factors": [0.02, 0.05, 0.5, 1]}
  })");
}

}  // namespace

TEST(Friction, TrescaBlockSticksBelowTheBoundAndSlidesAtBoundTimesLength) {
  const Result r = run(tresca_job());
  ASSERT_TRUE(r.converged) << r.message;
  const double capacity = 5 * 1.0;  // g x contact length (x thickness 1)
  bool some_stick_early = false;
  for (size_t k = 0; k < r.steps.size(); ++k) {
    const PairField& p = pair_of(r.steps[k], "c");
    const double F = std::abs(p.tangential_force);
    EXPECT_LE(F, capacity * (1 + 1e-10)) << "step " << k;
    if (k < 2) some_stick_early = some_stick_early || p.stick.sum() > 0;
    if (k >= 2) {  // pushed far enough: every node slides, the force is the bound times the length
      EXPECT_EQ(p.stick.sum(), 0) << "step " << k;
      EXPECT_NEAR(F, capacity, 1e-9 * capacity) << "step " << k;
      EXPECT_GT(p.slip.maxCoeff(), 0.0);
    }
  }
  EXPECT_TRUE(some_stick_early);
  // Sliding accumulates: the last step's slip exceeds the third's.
  EXPECT_GT(pair_of(r.steps[3], "c").slip.maxCoeff(), pair_of(r.steps[2], "c").slip.maxCoeff());
}

TEST(Friction, AForceFrictionCannotHoldStopsAtOnceNamingThePairAndTheRatio) {
  // The block pressed by 100 and pushed sideways by 40 with mu = 0.3: 40 / (0.3 x 100) = 1.333.
  json job = tresca_job();
  job["contacts"][0]["friction"] = {{"coefficient", 0.3}};
  job["bodies"][1]["boundary"] = json::parse(R"([{"edge": "top", "force": [40, -100]}])");
  job.erase("loading");
  const Result r = run(job);
  EXPECT_EQ(r.stop_reason, StopReason::error);
  EXPECT_TRUE(r.steps.empty());
  EXPECT_NE(r.message.find("contact 'c'"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("1.333 times"), std::string::npos) << r.message;
  EXPECT_LE(r.iterations, 1);
  // Below the bound (20 < 30) it holds, and the contact carries exactly the push.
  job["bodies"][1]["boundary"] = json::parse(R"([{"edge": "top", "force": [20, -100]}])");
  const Result held = run(job);
  ASSERT_TRUE(held.converged) << held.message;
  const PairField& p = pair_of(held.steps.back(), "c");
  EXPECT_NEAR(p.resultant.x(), -20, 1e-8 * 20);
  EXPECT_NEAR(p.resultant.y(), 100, 1e-8 * 100);
}

TEST(Friction, ZeroCoefficientIsTheFrictionlessSolution) {
  json job = contact::testing::example("hertz_force.json");
  const Result frictionless = run(job);
  job["contacts"][0]["friction"] = {{"coefficient", 0.0}};
  const Result zero = run(job);
  ASSERT_TRUE(frictionless.converged && zero.converged) << zero.message;
  for (size_t b = 0; b < 2; ++b)
    EXPECT_LT(relative(zero.steps.back().bodies[b].displacement, frictionless.steps.back().bodies[b].displacement),
              1e-10);
  const PairField& p = zero.steps.back().pairs[0];
  EXPECT_LT(relative(p.pressure, frictionless.steps.back().pairs[0].pressure), 1e-10);
  EXPECT_LT(p.tangential_traction.cwiseAbs().maxCoeff(), 1e-10 * p.pressure.maxCoeff());
}

TEST(Friction, ALargeCoefficientBondsLikeOneMergedBody) {
  // Two blocks on matching meshes, the upper one's top pushed sideways and down: with mu = 1e6 nothing slips, and
  // the displacements are those of one block meshed as the two together.
  const json two = json::parse(R"({
    "name": "bonded",
    "bodies": [
      {"name": "lower", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "nx": 6, "ny": 6}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
      {"name": "upper", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 1], [1, 1], [1, 2], [0, 2]], "nx": 6, "ny": 6}},
       "boundary": [{"edge": "top", "displacement": {"x": 0.01, "y": -0.02}}]}
    ],
    "contacts": [{"slave": "upper.bottom", "master": "lower.top", "friction": {"coefficient": 1e6}}]
  })");
  const json one = json::parse(R"({
    "name": "merged",
    "bodies": [
      {"name": "both", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 2], [0, 2]], "nx": 6, "ny": 12}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}},
                    {"edge": "top", "displacement": {"x": 0.01, "y": -0.02}}]}
    ]
  })");
  const Result bonded = run(two), merged = run(one);
  ASSERT_TRUE(bonded.converged && merged.converged) << bonded.message;
  const BodyField& m = merged.steps.back().bodies[0];
  double worst = 0;
  for (const auto& part : bonded.steps.back().bodies)
    for (int i = 0; i < part.mesh.num_nodes(); ++i)
      for (int j = 0; j < m.mesh.num_nodes(); ++j)
        if ((part.mesh.nodes[static_cast<size_t>(i)] - m.mesh.nodes[static_cast<size_t>(j)]).norm() < 1e-12)
          worst = std::max(worst, (part.displacement.row(i) - m.displacement.row(j)).norm());
  EXPECT_LT(worst, 1e-8 * m.displacement.cwiseAbs().maxCoeff());
  EXPECT_EQ(bonded.steps.back().pairs[0].stick.sum(), 7);  // every contact node
}

namespace {

// A half-cylinder (R = 2) pressed on a block and pushed sideways in three steps, non-matching meshes: partial
// slip, for comparing two solvers of the same discrete problem.
json pushed_cylinder(bool cylinder_is_slave) {
  json job = json::parse(R"({
    "name": "pushed",
    "bodies": [
      {"name": "block", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[-2, -2], [2, -2], [2, 0], [-2, 0]], "nx": 37, "ny": 9}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
      {"name": "cylinder", "material": {"E": 600, "nu": 0.25},
       "mesh": {"block": {"corners": [[-1.2, 0.4], [1.2, 0.4], [1.2, 2], [-1.2, 2]], "nx": 29, "ny": 8,
                          "edges": {"bottom": {"arc": {"center": [0, 2], "radius": 2}}}}},
       "boundary": [{"edge": "top", "displacement": {"y": -0.03}},
                    {"vertex": "top_left", "force": [1, 0], "history": [0, 0.5, 1]}]}
    ],
    "contacts": [{"name": "c", "slave": "cylinder.bottom", "master": "block.top", "friction": {"coefficient": 0.2}}],
    "loading": {"factors": [1, 1, 1]}
  })");
  if (!cylinder_is_slave) {
    job["contacts"][0]["slave"] = "block.top";
    job["contacts"][0]["master"] = "cylinder.bottom";
  }
  return job;
}

}  // namespace

TEST(Friction, InterfaceSolverEqualsTheMonolithicReferenceOnNonMatchingMeshesEitherWayRound) {
  for (bool cylinder_is_slave : {true, false}) {
    json job = pushed_cylinder(cylinder_is_slave);
    const Result interface = run(job);
    job["solver"] = {{"method", "monolithic"}};
    const Result monolithic = run(job);
    ASSERT_TRUE(interface.converged) << interface.message;
    ASSERT_TRUE(monolithic.converged) << monolithic.message;
    ASSERT_EQ(interface.steps.size(), 3u);
    bool partial_slip = false;
    for (size_t k = 0; k < 3; ++k) {
      const Step& a = interface.steps[k];
      const Step& b = monolithic.steps[k];
      for (size_t i = 0; i < a.bodies.size(); ++i)
        EXPECT_LT(relative(a.bodies[i].displacement, b.bodies[i].displacement), 1e-8) << "step " << k;
      const PairField& p = a.pairs[0];
      EXPECT_LT(relative(p.pressure, b.pairs[0].pressure), 1e-8);
      EXPECT_LT(relative(p.tangential_traction, b.pairs[0].tangential_traction), 1e-8) << "step " << k;
      EXPECT_EQ(p.stick, b.pairs[0].stick);
      if (k == 2) partial_slip = p.stick.sum() > 0 && (p.active - p.stick).sum() > 0;
    }
    EXPECT_TRUE(partial_slip) << "the last step should have both stick and slip";
  }
}

TEST(Friction, RollerBetweenPlatesLoadedByAForceAloneIsHeldByFriction) {
  // The naive roller of the frictionless diagnosis (test_job.cpp): with friction the job is accepted and solved.
  const json job = json::parse(R"({
    "name": "roller",
    "bodies": [
      {"name": "base", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-2, -1], [2, -1], [2, 0], [-2, 0]], "nx": 32, "ny": 8}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
      {"name": "roller", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-0.5, 0.1339745962155614], [0.5, 0.1339745962155614],
                                      [0.5, 1.8660254037844386], [-0.5, 1.8660254037844386]], "nx": 24, "ny": 24,
                          "edges": {"bottom": {"arc": {"center": [0, 1], "radius": 1}},
                                    "top": {"arc": {"center": [0, 1], "radius": 1}}}}}},
      {"name": "plate", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-2, 2], [2, 2], [2, 3], [-2, 3]], "nx": 32, "ny": 8}},
       "boundary": [{"edge": "top", "force": [0, -10000]}]}
    ],
    "contacts": [{"slave": "roller.bottom", "master": "base.top", "friction": {"coefficient": 0.2}},
                 {"slave": "roller.top", "master": "plate.bottom", "friction": {"coefficient": 0.2}}]
  })");
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  const Step& s = r.steps.back();
  const PairField& bottom = pair_of(s, "roller.bottom-base.top");
  const PairField& top = pair_of(s, "roller.top-plate.bottom");
  // Both contacts carry the whole load: the roller's bottom is pushed up by 10000, its top down.
  EXPECT_NEAR(bottom.resultant.y(), 10000, 1e-8 * 10000);
  EXPECT_NEAR(top.resultant.y(), -10000, 1e-8 * 10000);
  EXPECT_NEAR(bottom.resultant.x(), 0, 1e-8 * 10000);
  EXPECT_GT(bottom.active.sum(), 2);
  EXPECT_GT(top.active.sum(), 2);
  EXPECT_NEAR(body(s, "base").reaction_total.y(), 10000, 1e-8 * 10000);
}

TEST(Friction, CoarseFrictionSolvesStartEveryLoadStepNearItsStickAndSlipSets) {
  // The paper's test with Coulomb friction (mu 0.3) in four load steps, the upper body's top free in x: its
  // lateral expansion differs from the lower body's and the contact slips near its edges while the zone grows.
  // From "every node in contact sticks" the Newton moved each slip front by about a node per step (9 steps over
  // the four load steps here, 3.5 per load step at 256 x 64, 4 at 512 x 128); started from the coarse friction
  // solves (linalg/friction_nested.hpp) it needs 5 here, at most 1.5 per load step; the answer is still the
  // monolithic reference's.
  json job = contact::testing::example("seed_layers.json");
  job.erase("solver");
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = 128;
    b["mesh"]["block"]["ny"] = 32;
  }
  job["bodies"][0]["boundary"][1]["displacement"].erase("x");
  job["contacts"][0]["friction"] = {{"coefficient", 0.3}};
  job["loading"] = {{"factors", {0.25, 0.5, 0.75, 1.0}}};
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LE(r.iterations, 6) << "Newton steps over the four load steps";
  const PairField& p = r.steps.back().pairs.at(0);
  int in_contact = 0, sticking = 0;
  for (Eigen::Index j = 0; j < p.active.size(); ++j) {
    in_contact += p.active[j];
    sticking += p.active[j] && p.stick[j];
  }
  EXPECT_GT(in_contact - sticking, 0) << "some nodes slip (else the case tests nothing)";
  EXPECT_GT(sticking, 0);
  json reference = job;
  reference["solver"] = {{"method", "monolithic"}};
  const Result m = run(reference);
  ASSERT_TRUE(m.converged) << m.message;
  EXPECT_LE(relative(p.pressure, m.steps.back().pairs.at(0).pressure), 1e-8);
  EXPECT_LE(relative(p.tangential_traction, m.steps.back().pairs.at(0).tangential_traction), 1e-8);
}

TEST(LoadHistory, EachConditionFollowsItsOwnFactors) {
  // One block, bottom fixed: a downward force held while a sideways one grows from 0 and is then removed.
  const json job = json::parse(R"({
    "name": "history",
    "bodies": [
      {"name": "b", "material": {"E": 1000, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [1, 0], [1, 1], [0, 1]], "nx": 4, "ny": 4}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}},
                    {"edge": "top", "force": [0, -10], "history": [1, 1, 1]},
                    {"edge": "right", "force": [-4, 0], "history": [0, 1, 0]}]}
    ],
    "loading": {"factors": [0.5, 1, 2]}
  })");
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_EQ(r.steps.size(), 3u);
  const double expected_x[] = {0, 4, 0};
  for (size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d total = r.steps[k].bodies[0].reaction_total;
    EXPECT_NEAR(total.x(), expected_x[k], 1e-9) << "step " << k;
    EXPECT_NEAR(total.y(), 10, 1e-9) << "step " << k;  // held by its history, whatever the loading's factor
  }
  // Linearity: step 2 (the same loads as step 0) repeats step 0's field.
  EXPECT_LT(relative(r.steps[2].bodies[0].displacement, r.steps[0].bodies[0].displacement), 1e-12);
}
