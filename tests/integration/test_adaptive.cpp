// The adaptive loop: the paper's run on seed_layers, both strategies and indicators, the limits, and the cycle
// transcript (deal.II style: the per-step elements, DOFs and iterations are compared with a checked-in file).
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "adaptive_support.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;  // the shared helpers (support.hpp)

namespace {

// Number of cells whose centre lies in [x0, x1), and their largest level.
std::pair<int, int> cells_in(const BodyField& b, double x0, double x1) {
  int count = 0, level = -1;
  for (int c = 0; c < b.mesh.num_cells(); ++c) {
    double x = 0;
    for (int k : b.mesh.cells[static_cast<size_t>(c)]) x += 0.25 * b.mesh.nodes[static_cast<size_t>(k)].x();
    if (x < x0 || x >= x1) continue;
    ++count;
    level = std::max(level, b.mesh.level[static_cast<size_t>(c)]);
  }
  return {count, level};
}

}  // namespace

TEST(SeedLayersAdaptive, RefinesAtTheContactEdgeNeverInTheRightHalfAndMatchesAFineMesh) {
  const json job = example("seed_layers_adaptive.json");
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  ASSERT_GE(r.steps.size(), 3u);
  const Step& last = r.steps.back();
  const BodyField& lower = body(last, "lower");
  const BodyField& upper = body(last, "upper");
  // Only body 2 adapts (the paper): the upper body keeps its 32 x 8 mesh.
  EXPECT_EQ(upper.mesh.num_cells(), 32 * 8);
  // The right half of body 2 (x > 2), where there is no contact, is never refined (the paper) beyond the
  // neighbourhood of the contact zone (solver/adapt/contact_zones.hpp): x > 2.5 keeps its 3 x 2 initial cells, and
  // the cells next to x = 2, within one zone extent of the coarse first steps' zones, are split once at most.
  const auto right = cells_in(lower, 2.0, 4.0), far_right = cells_in(lower, 2.5, 4.0);
  EXPECT_EQ(far_right.first, 6);
  EXPECT_EQ(far_right.second, 0);
  EXPECT_LE(right.second, 1);
  // Refinement concentrates on the contact zone, the finest cells at its edge (x about 1). The contact's interior
  // is refined too: the paper explains its own interior refinements by stress gradients "and in places the error
  // of the mortar method" - here the master (the adapted body) is loaded by the dual multipliers of the coarse
  // slave, whose traction varies on the slave's element scale (docs/algorithm.md, "Mesh ratio").
  const auto edge = cells_in(lower, 0.8, 1.3), outside = cells_in(lower, 1.5, 2.0);
  EXPECT_EQ(edge.second, job["adaptivity"]["max_level"].get<int>());
  EXPECT_GT(edge.first, 4 * outside.first);
  // Every step carries the indicator of the adapted body.
  for (const auto& s : r.steps) EXPECT_EQ(body(s, "lower").indicator_cell.size(), body(s, "lower").mesh.num_cells());
  // The final contact pressure is within 2 % of a uniform fine-mesh solution of the same (penalty) problem.
  json fine = example("seed_layers.json");
  for (auto& b : fine["bodies"]) {
    b["mesh"]["block"]["nx"] = 128;
    b["mesh"]["block"]["ny"] = 32;
  }
  fine["solver"]["method"] = "monolithic";
  const Result ref = run(fine);
  ASSERT_TRUE(ref.converged);
  const auto& pa = last.pairs.at(0);
  const auto& pf = ref.steps.back().pairs.at(0);
  EXPECT_NEAR(pa.force, pf.force, 0.02 * pf.force);
  EXPECT_NEAR(pa.pressure.maxCoeff(), pf.pressure.maxCoeff(), 0.02 * pf.pressure.maxCoeff());
}

TEST(Adaptivity, ConvergeThenRefineWithBothIndicatorsRefinesTowardsTheContactAndStops) {
  for (const char* indicator : {"fem_bem", "zz"}) {
    json job = example("seed_layers_adaptive.json");
    job["adaptivity"]["strategy"] = "converge_then_refine";
    job["adaptivity"]["indicator"] = indicator;
    job["solver"] = {
        {"method", "interface_newton"}, {"enforcement", "penalty"}, {"penalty", {{"c", 0.05}, {"length", 1}}}};
    const Result r = run(job);
    ASSERT_TRUE(r.converged) << indicator << ": " << r.message;
    ASSERT_GE(r.steps.size(), 3u) << indicator;
    for (size_t k = 1; k < r.steps.size(); ++k)
      EXPECT_GT(body(r.steps[k], "lower").mesh.num_cells(), body(r.steps[k - 1], "lower").mesh.num_cells())
          << indicator;
    // x > 2.5 is never refined; next to x = 2 the neighbourhood of the first steps' zones splits cells once at most.
    EXPECT_EQ(cells_in(body(r.steps.back(), "lower"), 2.5, 4.0).first, 6) << indicator;
    EXPECT_LE(cells_in(body(r.steps.back(), "lower"), 2.0, 4.0).second, 1) << indicator;
    // Each step's report says how many elements were refined.
    int refined = 0;
    for (const auto& it : r.history) refined += it.bodies[1].elements_refined;
    EXPECT_GT(refined, 0);
  }
}

TEST(Adaptivity, MaxDofsIsNeverExceededAndIsReported) {
  json job = example("seed_layers_adaptive.json");
  job["adaptivity"]["strategy"] = "converge_then_refine";
  job["adaptivity"]["max_dofs"] = 200;
  job["adaptivity"]["stop_tolerance"] = 0;  // the cut-back steps change little: only the limit is tested here
  job["solver"] = {{"method", "interface_newton"}, {"enforcement", "penalty"}};
  const Result r = run(job);
  ASSERT_FALSE(r.steps.empty()) << r.message;
  for (const auto& s : r.steps) EXPECT_LE(2 * body(s, "lower").mesh.num_nodes(), 200);
  EXPECT_NE(r.message.find("max_dofs"), std::string::npos) << r.message;
}

TEST(Adaptivity, MaxLevelCapsTheRefinement) {
  json job = example("seed_layers_adaptive.json");
  job["adaptivity"]["max_level"] = 2;
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  for (int l : body(r.steps.back(), "lower").mesh.level) EXPECT_LE(l, 2);
}

TEST(Adaptivity, CycleTranscriptMatchesTheCheckedInExpectedOutput) {
  // A small adaptive run's per-step transcript (elements, DOFs per body, solver iterations): any unintended
  // change of the adaptive behaviour changes it. Regenerate deliberately with CONTACT_UPDATE_TRANSCRIPT=1.
  json job = example("seed_layers_adaptive.json");
  job["adaptivity"]["strategy"] = "converge_then_refine";
  job["adaptivity"]["max_steps"] = 4;
  job["solver"] = {{"method", "interface_newton"}, {"enforcement", "penalty"}};
  const Result r = run(job);
  ASSERT_FALSE(r.steps.empty()) << r.message;
  std::ostringstream os;
  int previous_iteration = 0;
  for (const auto& s : r.steps) {
    // Unknowns after the constraints (Dirichlet and hanging nodes), from the step's last iteration report.
    const IterationReport* rep = nullptr;
    for (const auto& it : r.history)
      if (it.iteration == s.iteration) rep = &it;
    ASSERT_NE(rep, nullptr);
    os << "step " << s.index;
    for (size_t a = 0; a < s.bodies.size(); ++a)
      os << " | " << s.bodies[a].name << ": " << s.bodies[a].mesh.num_cells() << " cells, " << rep->bodies[a].dofs
         << " dofs";
    os << " | iterations " << s.iteration - previous_iteration << "\n";
    previous_iteration = s.iteration;
  }
  const std::string path = std::string(CONTACT_SOURCE_DIR) + "/tests/data/adaptive_transcript.txt";
  if (std::getenv("CONTACT_UPDATE_TRANSCRIPT")) std::ofstream(path) << os.str();
  std::ifstream in(path);
  ASSERT_TRUE(in.good()) << "missing " << path;
  std::stringstream expected;
  expected << in.rdbuf();
  EXPECT_EQ(os.str(), expected.str());
}

namespace {

// Records the adaptive step reports; cancels the token at the report of step `cancel_at` (never if < 0).
class StepRecorder final : public Observer {
 public:
  StepRecorder(CancelToken& cancel, int cancel_at) : cancel_(cancel), cancel_at_(cancel_at) {}
  void on_adaptive_step(const AdaptiveStepReport& r) override {
    reports.push_back(r);
    if (r.step == cancel_at_) cancel_.cancel();
  }
  std::vector<AdaptiveStepReport> reports;

 private:
  CancelToken& cancel_;
  int cancel_at_;
};

json converge_then_refine_job() {
  json job = example("seed_layers_adaptive.json");
  job["adaptivity"]["strategy"] = "converge_then_refine";
  job["solver"] = {
      {"method", "interface_newton"}, {"enforcement", "penalty"}, {"penalty", {{"c", 0.05}, {"length", 1}}}};
  return job;
}

Result run_recorded(const json& job, StepRecorder& recorder, CancelToken& cancel) {
  return solve(parse_or_fail(job), recorder, cancel);
}

}  // namespace

TEST(AdaptiveStop, StopsOnceTheAnswerSettledAgainstAStepWithHalfTheUnknownsAtTwoStepsInARow) {
  // Issue 50, item 1: the stop reads what the user reads (each pair's force, peak pressure and contact zone; with
  // friction the stick zone and the tangential force), each step against the last with at most half its
  // unknowns (adapt/settled.hpp).
  for (const double tolerance : {0.05, 0.005}) {
    json job = converge_then_refine_job();
    job["adaptivity"]["stop_tolerance"] = tolerance;
    CancelToken cancel;
    StepRecorder recorder(cancel, -1);
    const Result r = run_recorded(job, recorder, cancel);
    ASSERT_TRUE(r.converged) << r.message;
    // One report per mesh state, in order, with that state's cells.
    ASSERT_EQ(recorder.reports.size(), r.steps.size());
    for (size_t k = 0; k < r.steps.size(); ++k) {
      EXPECT_EQ(recorder.reports[k].step, static_cast<int>(k));
      EXPECT_EQ(recorder.reports[k].bodies[1].elements, body(r.steps[k], "lower").mesh.num_cells());
      EXPECT_GT(recorder.reports[k].bodies[1].dofs, 0);
      EXPECT_GT(recorder.reports[k].estimate, 0.0);
    }
    const auto largest = [](const AdaptiveStepReport& s) {
      return std::max({s.force_change, s.peak_change, s.extent_change, s.stick_change, s.tangential_change});
    };
    const auto settled = [&](const AdaptiveStepReport& s) { return s.compared_with >= 0 && largest(s) < tolerance; };
    // The stop: the last two steps settled, and no two steps in a row before.
    ASSERT_GE(recorder.reports.size(), 3u);
    const AdaptiveStepReport& last = recorder.reports.back();
    ASSERT_NE(r.message.find("the answer settled"), std::string::npos) << tolerance << ": " << r.message;
    EXPECT_TRUE(settled(last));
    EXPECT_TRUE(settled(recorder.reports[recorder.reports.size() - 2]));
    for (size_t k = 1; k + 1 < recorder.reports.size(); ++k)
      EXPECT_FALSE(settled(recorder.reports[k]) && settled(recorder.reports[k - 1])) << "step " << k;
    // Each step is compared with the last one with at most half its unknowns (2 x nodes), and its changes are
    // those of the two steps' fields (one pair: its force and peak against the larger of the two).
    for (size_t k = 0; k < r.steps.size(); ++k) {
      const AdaptiveStepReport& s = recorder.reports[k];
      const double n = static_cast<double>(mesh_unknowns(r.steps[k]));
      int expected = -1;
      for (size_t j = 0; j < k; ++j)
        if (static_cast<double>(mesh_unknowns(r.steps[j])) <= 0.5 * n) expected = static_cast<int>(j);
      ASSERT_EQ(s.compared_with, expected) << "step " << k;
      if (expected < 0) {
        EXPECT_TRUE(std::isnan(s.force_change)) << "step " << k;
        continue;
      }
      const PairField &now = r.steps[k].pairs.at(0), &before = r.steps[static_cast<size_t>(expected)].pairs.at(0);
      EXPECT_NEAR(s.force_change, std::abs(now.force - before.force) / std::max(now.force, before.force), 1e-12);
      const double p1 = now.pressure.maxCoeff(), p0 = before.pressure.maxCoeff();
      EXPECT_NEAR(s.peak_change, std::abs(p1 - p0) / std::max(p1, p0), 1e-12);
      EXPECT_EQ(s.stick_change, 0.0);  // frictionless
      EXPECT_EQ(s.tangential_change, 0.0);
    }
  }
}

TEST(AdaptiveStop, SaysWhenNothingMarkedCanBeRefined) {
  json job = converge_then_refine_job();
  job["adaptivity"]["max_level"] = 0;  // every cell over delta is at the level limit
  job["adaptivity"]["stop_tolerance"] = 0;
  const Result r = run(job);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.steps.size(), 1u);
  EXPECT_NE(r.message.find("nothing marked can be refined after 0 refinement steps"), std::string::npos) << r.message;
}

TEST(AdaptiveStop, ACancelBetweenStepsStopsWithTheStepsSoFar) {
  json job = converge_then_refine_job();
  job["adaptivity"]["stop_tolerance"] = 0;
  CancelToken cancel;
  StepRecorder recorder(cancel, 1);  // cancelled once step 1 is reported: its refined meshes are assembled next
  const Result r = run_recorded(job, recorder, cancel);
  EXPECT_EQ(r.stop_reason, StopReason::cancelled) << r.message;
  // Steps 0 and 1 complete; step 2's meshes are neither assembled nor solved (the cancel stops the assembly).
  ASSERT_EQ(r.steps.size(), 2u) << r.message;
  EXPECT_GT(body(r.steps[1], "lower").mesh.num_cells(), body(r.steps[0], "lower").mesh.num_cells());
  EXPECT_NE(r.message.find("cancelled during adaptive step 2 (assembling and factorising its refined meshes; the "
                           "result holds step 1's solution)"),
            std::string::npos)
      << r.message;
}

TEST(TwoCylindersGmshAdaptive, FemBemStopsByItselfAtTheCostOfAFewZzRunsAndMeetsHertzWithFewerUnknownsThanUniform) {
  // api/examples/two_cylinders_gmsh.json (issue 20): a steel half-cylinder R1 = 10 on an aluminium one R2 = 25,
  // Gmsh triangles from a coarse start (~1.4k unknowns), the job's defaults with fem_bem, then the same with zz.
  // Plane-strain Hertz for two cylinders: 1/R* = 1/R1 + 1/R2, 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2,
  // a = sqrt(4 P R* / (pi E*)), p0 = 2 P / (pi a), with P the computed contact force.
  const json job = example("two_cylinders_gmsh.json");
  ASSERT_EQ(job["adaptivity"]["indicator"], "fem_bem");
  // Wall times, each the shorter of two runs, alternating (the machine may be shared: a run slowed by another
  // process's burst says nothing about the indicators).
  json zz_job = job;
  zz_job["adaptivity"]["indicator"] = "zz";
  Result fem_bem, zz;
  double fem_bem_seconds = HUGE_VAL, zz_seconds = HUGE_VAL;
  for (int repeat = 0; repeat < 2; ++repeat)
    for (const bool bem : {true, false}) {
      const auto t0 = std::chrono::steady_clock::now();
      Result r = run(bem ? job : zz_job);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      (bem ? fem_bem_seconds : zz_seconds) = std::min(bem ? fem_bem_seconds : zz_seconds, seconds);
      (bem ? fem_bem : zz) = std::move(r);
    }
  long coarse = 0;
  for (const auto& b : fem_bem.history.front().bodies) coarse += b.dofs;
  std::printf("  coarse %ld unknowns; fem_bem %zu steps %.2f s (indicator %.2f s), zz %zu steps %.2f s: ratio %.2f\n",
              coarse, fem_bem.steps.size(), fem_bem_seconds, fem_bem.indicator_seconds, zz.steps.size(), zz_seconds,
              fem_bem_seconds / zz_seconds);
  EXPECT_GT(coarse, 1200);
  EXPECT_LT(coarse, 1600);
  for (const Result* r : {&fem_bem, &zz}) {
    ASSERT_TRUE(r->converged) << r->message;
    EXPECT_NE(r->message.find("all below stop_tolerance"), std::string::npos) << r->message;  // stopped by itself
  }
  // A guard, not the measurement: on a shared 2-core machine the ratio of two wall times moves by a third (2.33 to
  // 2.85 measured with the neighbourhood rule, 2.41 without; docs/bem.md), so the bound only catches a return to
  // the dense BEM's 30-70x.
  EXPECT_LE(fem_bem_seconds, 5.0 * zz_seconds);
  const PairField& pair = fem_bem.steps.back().pairs.at(0);
  const double R = 1.0 / (1.0 / 10 + 1.0 / 25);
  const double inv_E = (1 - 0.3 * 0.3) / 2.1e5 + (1 - 0.33 * 0.33) / 7.0e4;
  const double a = std::sqrt(4 * pair.force * R * inv_E / M_PI), p0 = 2 * pair.force / (M_PI * a);
  const double peak = pair.pressure.maxCoeff();
  std::printf("  P = %.3f, Hertz a = %.4f p0 = %.2f; computed peak %.2f (%.3f %%), half-width %.4f\n", pair.force, a,
              p0, peak, 100 * (peak - p0) / p0, contact::testing::hertz_half_width(pair));
  EXPECT_NEAR(peak, p0, 0.003 * p0);
  EXPECT_NEAR(contact::testing::hertz_half_width(pair), a, 0.003 * a);
  // Equilibrium of each body on the refined meshes: its supports' reactions balance the contact's resultant
  // (steel: loaded by the contact and its top only; aluminium: by the contact and its base). The supports touch
  // refined cells whose hanging nodes pass part of their residual to the supported nodes: left out, the
  // reactions were 4 % off (956 and 1019 against 1000.5).
  for (const auto& body : fem_bem.steps.back().bodies) {
    const double sign = body.name == "steel" ? 1.0 : -1.0;  // the steel is the slave: the resultant acts on it
    EXPECT_NEAR(body.reaction_total.y(), -sign * pair.resultant.y(), 1e-8 * pair.force) << body.name;
    EXPECT_NEAR(body.reaction_total.x(), -sign * pair.resultant.x(), 1e-8 * pair.force) << body.name;
  }

  // Issue 30: the last step within 0.3 % of Hertz in peak and half-width with fewer unknowns than the graded start
  // refined uniformly needs for the same. Uniform refinement: every cell refined at every step (delta below any
  // indicator, plain marking), each level kept (output.steps "all"); the first level within 0.3 % in both.
  const Result levels = contact::testing::uniform_levels(job, 4);
  ASSERT_TRUE(levels.converged) << levels.message;
  ASSERT_EQ(levels.steps.size(), 5u);
  const auto unknowns = contact::testing::mesh_unknowns;
  auto within = [&](const PairField& q, double tolerance) {
    const double qa = std::sqrt(4 * q.force * R * inv_E / M_PI), qp0 = 2 * q.force / (M_PI * qa);
    const double width = contact::testing::hertz_half_width(q);
    return std::abs(q.pressure.maxCoeff() - qp0) <= tolerance * qp0 && std::abs(width - qa) <= tolerance * qa;
  };
  long uniform_needs = 0;
  for (size_t k = 0; k < levels.steps.size() && !uniform_needs; ++k) {
    const PairField& q = levels.steps[k].pairs.at(0);
    std::printf("  uniform level %zu: %ld unknowns, %s\n", k, unknowns(levels.steps[k]),
                within(q, 0.003) ? "within 0.3 %" : "not within 0.3 %");
    if (within(q, 0.003)) uniform_needs = unknowns(levels.steps[k]);
  }
  const long adaptive = unknowns(fem_bem.steps.back());
  std::printf("  adaptive last step %ld unknowns; uniform refinement first within 0.3 %% at %ld\n", adaptive,
              uniform_needs);
  ASSERT_GT(uniform_needs, 0) << "no uniform level within 0.3 %: refine further";
  EXPECT_LT(adaptive, uniform_needs);
}

TEST(AdaptiveLimits, RefinementStaysWithinTheJobsLimitOnUnknownsOverAllBodies) {
  // Issue 32, item 3: adaptivity.max_dofs is per body, so a job admitted under --max-dofs N (job::Limits) could
  // refine to many times N. The paper's adaptive run, each body allowed 2500 unknowns: without a total limit it
  // ends above 2500 in all; under a limit of 2500 every step stays within it, and the run says so.
  nlohmann::json job = contact::testing::example("seed_layers_adaptive.json");
  job["adaptivity"]["max_dofs"] = 2500;
  auto total_of = [](const Step& step) {
    long dofs = 0;
    for (const auto& body : step.bodies) dofs += 2L * body.mesh.num_nodes();
    return dofs;
  };
  const Result free = contact::testing::run(job);
  ASSERT_TRUE(free.converged) << free.message;
  EXPECT_GT(total_of(free.steps.back()), 2500);  // the test means something: the per-body limit alone allows more

  job::Limits limits;
  limits.max_dofs = 2500;
  auto parsed = job::parse(job, limits);
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  CancelToken cancel;
  std::vector<IterationReport> reports;
  struct Collect : Observer {
    std::vector<IterationReport>& out;
    explicit Collect(std::vector<IterationReport>& o) : out(o) {}
    void on_iteration(const IterationReport& r) override { out.push_back(r); }
  } collect(reports);
  const Result bounded = solve(*parsed.problem, collect, cancel);
  ASSERT_TRUE(bounded.converged) << bounded.message;
  for (const Step& step : bounded.steps) EXPECT_LE(total_of(step), 2500);
  bool said = false;
  for (const auto& r : reports)
    said = said || r.note.find("2500 unknowns over all bodies (--max-dofs) reached") != std::string::npos;
  EXPECT_TRUE(said) << "no report names the total limit";
}

TEST(AdaptiveLimits, RefinementStaysWithinTheJobsLimitOnTheInterfacesMemory) {
  // Issue 51, item 3: the interface problem's memory (method interface_newton: dense blocks over each body's
  // contact unknowns, estimate_interface_memory) was checked on the first mesh only, and refinement at the contact
  // makes it grow with the square of the contact edges' nodes. The paper's layers by interface Newton, adaptive:
  // without a limit they refine past it; under a limit of three times the first mesh's estimate every step stays
  // within it, and the run says why it stopped refining.
  nlohmann::json job = contact::testing::example("seed_layers_adaptive.json");
  job["solver"] = {{"method", "interface_newton"}};
  job["adaptivity"] = {{"indicator", "fem_bem"}, {"max_level", 6}};
  const auto estimate_of = [](const Problem& problem, const Step& step) {
    return estimate_interface_memory(
               problem.contacts, step.bodies.size(),
               [&](int body, const std::string& edge) {
                 return static_cast<double>(step.bodies[static_cast<size_t>(body)].mesh.edge_set_nodes(edge).size());
               })
        .bytes;
  };
  auto first = job::parse(job);
  ASSERT_TRUE(first.ok()) << job::format_errors(first.errors);
  const double start = estimate_interface_memory(
                           first.problem->contacts, first.problem->bodies.size(),
                           [&](int body, const std::string& edge) {
                             return static_cast<double>(
                                 first.problem->bodies[static_cast<size_t>(body)].mesh.edge_set_nodes(edge).size());
                           })
                           .bytes;
  const double limit = 3.0 * start;
  const Result free = contact::testing::run(job);
  ASSERT_TRUE(free.converged) << free.message;
  EXPECT_GT(estimate_of(*first.problem, free.steps.back()), limit);  // the limit means something

  job::Limits limits;
  limits.max_interface_bytes = limit;
  auto parsed = job::parse(job, limits);
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  const Result bounded = contact::testing::solve_quietly(*parsed.problem);
  ASSERT_TRUE(bounded.converged) << bounded.message;
  ASSERT_GE(bounded.steps.size(), 2u) << bounded.message;  // it refined while the limit allowed
  for (const Step& step : bounded.steps) EXPECT_LE(estimate_of(*parsed.problem, step), limit);
  EXPECT_NE(bounded.message.find("(--max-interface-bytes): refinement stopped"), std::string::npos) << bounded.message;
}
