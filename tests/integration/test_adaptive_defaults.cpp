// Issue 50: adaptivity's defaults (the goal-oriented marking, stopped where the answer settled: adapt/settled.hpp)
// on the paper's test, Cattaneo-Mindlin and the two-cylinder example: each last step within what the defaults aim
// at (docs/job-format.md, "What the defaults aim at") and with at most 3x the unknowns of a target run that meets the
// same accuracy; the paper's test against uniform refinement. Errors against mathematics (Hertz, Mindlin) or an
// independent solution (the paper's test: an overkill run of the indicator's marking), never against this code's
// earlier output.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "adaptive_support.hpp"
#include "cattaneo_mindlin.hpp"
#include "support.hpp"
#include "target_runs.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;

namespace {

struct Estimates final : Observer {
  std::vector<double> of_step;
  void on_adaptive_step(const AdaptiveStepReport& r) override { of_step.push_back(r.pressure_estimate); }
};

using contact::testing::target_run_for;
using Stop = contact::testing::TargetStop;

// The example with every adaptivity default; then a run with a target below the defaults' last error, each of its
// steps kept, and the target run that meets that error. Returns the defaults' run.
Result defaults_against_target(json job, const std::function<double(const Step&)>& error, const char* name) {
  job["adaptivity"] = json::object();
  const Result d = run(job);
  EXPECT_TRUE(d.converged) << name << ": " << d.message;
  // Stopped by itself: the answer settled, or the level limit left nothing of the pressure's error to refine
  // (Cattaneo-Mindlin from 20 x 4: its contact zone is narrower than one first cell, and its stick-slip points reach
  // level 8 about when the answer settles, so either stop comes first from run to run; docs/algorithm.md,
  // "Reproducibility").
  EXPECT_TRUE(d.message.find("the answer settled") != std::string::npos ||
              d.message.find("cells at max_level not refined") != std::string::npos)
      << name << ": " << d.message;
  if (d.steps.empty()) return d;
  const double e = error(d.steps.back());
  const long n = mesh_unknowns(d.steps.back());
  job["adaptivity"] = {{"target_error", 0.6 * e}};
  job["output"] = {{"steps", "all"}};
  Estimates estimates;
  CancelToken cancel;
  const Result t = solve(parse_or_fail(job), estimates, cancel);
  EXPECT_TRUE(t.converged) << name << ": " << t.message;
  std::vector<Stop> steps;
  for (size_t k = 0; k < t.steps.size() && k < estimates.of_step.size(); ++k)
    steps.push_back({mesh_unknowns(t.steps[k]), error(t.steps[k]), estimates.of_step[k]});
  const long target = target_run_for(steps, e);
  std::printf(
      "  %s: the defaults stop after %zu steps at %ld unknowns (2 x nodes) with the pressure %.3f %% wrong; "
      "the target run that meets %.3f %% stops at %ld: ratio %.2f\n",
      name, d.steps.back().index + 1UL, n, 100 * e, 100 * e, target,
      static_cast<double>(n) / static_cast<double>(target));
  EXPECT_GT(target, 0) << name;
  EXPECT_LE(n, 3 * target) << name;
  return d;
}

}  // namespace

TEST(AdaptiveDefaults, CattaneoMindlinStopsOnTheTheoryWithinThreeTimesTheUnknownsOfATargetRunAsAccurate) {
  const double Q = 0.5 * 0.3 * 2194.0;  // P is 2194 to 0.1 % on fine meshes (the held top sets it)
  const Result d = defaults_against_target(
      cattaneo_mesh(20, 4, false, Q), [](const Step& s) { return hertz_pressure_error(s.pairs.at(0)); },
      "Cattaneo-Mindlin");
  ASSERT_FALSE(d.steps.empty());
  // What the defaults aim at: the pressure within 0.5 % of Hertz's (L2), the force within 0.5 %, the stick zone
  // within 1 % of the contact's half-width of Mindlin's, the tangential traction within 5 % of Mindlin's (L2).
  const PairField& p = d.steps.back().pairs.at(0);
  const MindlinFit fit = mindlin_fit(p, Q);
  std::printf("  P %.2f, c / a %.4f (theory %.4f), traction %.2f %%, pressure %.3f %%\n", p.force, fit.c_over_a,
              fit.theory, 100 * fit.traction_error, 100 * hertz_pressure_error(p));
  EXPECT_LE(hertz_pressure_error(p), 0.005);
  EXPECT_NEAR(p.force, 2194.0, 0.005 * 2194.0);
  EXPECT_NEAR(fit.c_over_a, fit.theory, 0.01);
  EXPECT_LT(fit.traction_error, 0.05);
  EXPECT_NEAR(-p.weight.dot(p.tangential_traction), Q, 1e-8 * Q);
}

TEST(AdaptiveDefaults, TwoCylindersStopOnHertzWithinThreeTimesTheUnknownsOfATargetRunAsAccurate) {
  // api/examples/two_cylinders_gmsh.json without its own adaptivity: plane-strain Hertz for a steel R 10 on an
  // aluminium R 25 at the computed force (1/R* = 1/R1 + 1/R2, 1/E* = sum (1 - nu^2) / E, a = sqrt(4 P R* / (pi E*)),
  // p0 = 2 P / (pi a)); the half-cylinders are 25 half-widths and more deep, their departure from Hertz's half-planes
  // ~0.02 % at the finest meshes measured (bench_adaptivity).
  const double R = 1.0 / (1.0 / 10 + 1.0 / 25), inv_E = (1 - 0.3 * 0.3) / 2.1e5 + (1 - 0.33 * 0.33) / 7.0e4;
  const auto hertz = [&](const PairField& q) {
    const double a = std::sqrt(4 * q.force * R * inv_E / M_PI), p0 = 2 * q.force / (M_PI * a);
    return std::pair{a, p0};
  };
  const auto error = [&](const Step& s) {
    const PairField& q = s.pairs.at(0);
    const auto [a, p0] = hertz(q);
    return profile_error(q, q.pressure, a,
                         [&](double x) { return p0 * std::sqrt(std::max(0.0, 1 - x * x / (a * a))); });
  };
  const Result d = defaults_against_target(example("two_cylinders_gmsh.json"), error, "two cylinders");
  ASSERT_FALSE(d.steps.empty());
  const PairField& q = d.steps.back().pairs.at(0);
  const auto [a, p0] = hertz(q);
  std::printf("  peak %.3f %% from Hertz, half-width %.3f %%\n", 100 * (q.pressure.maxCoeff() - p0) / p0,
              100 * (hertz_half_width(q) - a) / a);
  EXPECT_LE(error(d.steps.back()), 0.005);
  EXPECT_NEAR(q.pressure.maxCoeff(), p0, 0.005 * p0);
  EXPECT_NEAR(hertz_half_width(q), a, 0.005 * a);
}

TEST(AdaptiveDefaults, ThePapersTestEndsCloserToTheSolutionThanUniform512x128WithTwentyTimesFewerUnknowns) {
  // Issue 50, item 2. The reference: the overkill run of the indicator's marking (seed_layers_overkill: within
  // ~0.01 % of the solution), independent of the defaults' goal-oriented marking. Uniform
  // meshes 64 x 16 .. 512 x 128 measured against it; unknowns counted as 2 x nodes on both sides.
  const Result over = run(seed_layers_overkill());
  ASSERT_TRUE(over.converged) << over.message;
  const PressureProfile reference(over.steps.back().pairs.at(0));
  std::vector<std::pair<long, double>> uniform;  // unknowns, error
  Result finest;
  for (const int nx : {64, 128, 256, 512}) {
    Result r = run(seed_layers_defaults(nx));
    ASSERT_TRUE(r.converged) << nx << ": " << r.message;
    uniform.emplace_back(mesh_unknowns(r.steps.back()), pressure_error(r.steps.back().pairs.at(0), reference));
    if (nx == 512) finest = std::move(r);
  }
  for (size_t i = 1; i < uniform.size(); ++i) ASSERT_LT(uniform[i].second, uniform[i - 1].second);  // converging

  json job = seed_layers_defaults(8);
  const auto error = [&](const Step& s) { return pressure_error(s.pairs.at(0), reference); };
  const Result d = defaults_against_target(job, error, "the paper's test");
  ASSERT_FALSE(d.steps.empty());
  const Step& last = d.steps.back();
  const double e = error(last);
  const long n = mesh_unknowns(last);
  // The uniform unknowns for that error: log-log between the measured meshes around it; below the finest mesh's
  // error, at least the finest mesh's unknowns (a lower bound).
  double needed = static_cast<double>(uniform.back().first);
  for (size_t i = 0; i + 1 < uniform.size(); ++i) {
    const auto [n0, e0] = uniform[i];
    const auto [n1, e1] = uniform[i + 1];
    if (e <= e0 && e >= e1)
      needed = n0 * std::exp(std::log(static_cast<double>(n1) / n0) * std::log(e / e0) / std::log(e1 / e0));
  }
  ASSERT_LE(e, uniform.front().second);
  // The issue's literal measure, against uniform 512 x 128 itself: that mesh is 0.2 % from the overkill (the
  // square-root edge on h = 1/128), so an answer closer to the solution than it reads as about that error and the
  // ratio saturates. Printed, not asserted.
  const PressureProfile issue_reference(finest.steps.back().pairs.at(0));
  std::printf(
      "  the defaults' last step: %ld unknowns, %.3f %% from the overkill (uniform 512 x 128: %.3f %%); uniform "
      "needs %s%.0f: ratio %s%.1f. Against 512 x 128 itself: %.3f %%\n",
      n, 100 * e, 100 * uniform.back().second, e < uniform.back().second ? ">" : "", needed,
      e < uniform.back().second ? ">" : "", needed / static_cast<double>(n),
      100 * pressure_error(last.pairs.at(0), issue_reference));
  EXPECT_GE(needed, 20.0 * static_cast<double>(n));
  // What the defaults aim at: the pressure within 0.5 % (L2), the force and the peak pressure within 0.5 %.
  EXPECT_LE(e, 0.005);
  const PairField &p = last.pairs.at(0), &o = over.steps.back().pairs.at(0);
  EXPECT_NEAR(p.force, o.force, 0.005 * o.force);
  EXPECT_NEAR(p.pressure.maxCoeff(), o.pressure.maxCoeff(), 0.005 * o.pressure.maxCoeff());
}
