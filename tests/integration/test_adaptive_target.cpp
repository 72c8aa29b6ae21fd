// Issue 30, item 2: an adaptive run that stops at the accuracy the job asks for (adaptivity.target_error), with
// an estimate of the contact pressure's error (solver/adapt/pressure_estimate.hpp) checked against the true error
// of the paper's test, measured against an independent overkill solution.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "adaptive_support.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace contact;
using nlohmann::json;
using namespace contact::testing;

namespace {

class Estimates final : public Observer {
 public:
  void on_adaptive_step(const AdaptiveStepReport& r) override { pressure.push_back(r.pressure_estimate); }
  std::vector<double> pressure;
};

// The job solved with every step kept, each step's pressure estimate in `estimates`; it must meet its target.
Result run_to_target(json job, Estimates& estimates) {
  job["output"] = {{"steps", "all"}};
  CancelToken cancel;
  Result r = solve(parse_or_fail(job), estimates, cancel);
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_NE(r.message.find("target met after"), std::string::npos) << r.message;
  EXPECT_EQ(estimates.pressure.size(), r.steps.size());
  return r;
}

// The errors a job gets at validation, as "pointer: message" lines.
std::string validation_errors(const json& job) {
  const auto parsed = job::parse(job);
  std::string out;
  for (const auto& e : parsed.errors) out += e.pointer + ": " + e.message + "\n";
  return out;
}

}  // namespace

TEST(AdaptiveTarget, ThePapersTestReachesATenthOfAPercentWithTenTimesFewerUnknownsThanUniformAndTheEstimateIsTrue) {
  // The reference: an overkill adaptive run that does not use the pressure estimate (the stress indicator with
  // delta 0.01 and 11 levels, 9 steps: ~195k unknowns, the contact edge at h = 1/4096). Its last step is within
  // ~0.01 % of the solution (measured against a run two steps further: 0.0024 %; uniform 2048 x 512 is 0.027 %
  // off it, the square-root edge's sqrt(1/10) h / a for h = 1/2048 being 0.015 %).
  const Result fine = run(seed_layers_overkill());
  ASSERT_TRUE(fine.converged) << fine.message;
  const PressureProfile reference(fine.steps.back().pairs.at(0));

  // Uniform 512 x 128 (262,400 unknowns) is still above 0.1 %: uniform meshes need more than that for it.
  const Result uniform = run(seed_layers_defaults(512));
  ASSERT_TRUE(uniform.converged) << uniform.message;
  const double uniform_error = pressure_error(uniform.steps.back().pairs.at(0), reference);
  const long uniform_dofs = unknowns(uniform, uniform.iterations);
  EXPECT_GT(uniform_error, 0.001);

  json job = seed_layers_defaults(8);
  job["adaptivity"] = {{"target_error", 0.001}};
  Estimates estimates;
  const Result r = run_to_target(job, estimates);
  ASSERT_EQ(estimates.pressure.size(), r.steps.size());
  // It stops at the first step whose estimate meets the target.
  for (size_t k = 0; k + 1 < r.steps.size(); ++k) EXPECT_GT(estimates.pressure[k], 0.001) << "step " << k;
  EXPECT_LE(estimates.pressure.back(), 0.001);
  // The estimate is the error: effectivity (estimate / true error) between 0.6 and 2.5 at every step whose error
  // is well above the reference's own. Measured 0.68 to 1.11 with the goal-oriented marking of a target (1.04 to
  // 1.9 with the stress indicator's marking, which refined the contact surface further than the pressure needed
  // and so left less of the error the boundary-element correction cannot see: the surface's own discretisation,
  // which the boundary elements share; docs/algorithm.md, "Refinement for the pressure's target").
  for (size_t k = 0; k < r.steps.size(); ++k) {
    const double error = pressure_error(r.steps[k].pairs.at(0), reference);
    std::printf("  step %zu: %ld unknowns, estimate %.4f %%, error %.4f %%, effectivity %.2f\n", k,
                unknowns(r, r.steps[k].iteration), 100 * estimates.pressure[k], 100 * error,
                estimates.pressure[k] / error);
    if (error > 0.0005) {
      EXPECT_GT(estimates.pressure[k], 0.6 * error) << "step " << k;
      EXPECT_LT(estimates.pressure[k], 2.5 * error) << "step " << k;
    }
  }
  // The last step's true error meets the target, with a tenth of the unknowns uniform meshes need at least.
  const double error = pressure_error(r.steps.back().pairs.at(0), reference);
  const long dofs = unknowns(r, r.steps.back().iteration);
  std::printf("  last step %ld unknowns, error %.4f %%; uniform 512 x 128: %ld unknowns, error %.4f %%\n", dofs,
              100 * error, uniform_dofs, 100 * uniform_error);
  EXPECT_LE(error, 0.001);
  EXPECT_LE(10 * dofs, uniform_dofs);
}

TEST(AdaptiveTarget, TwoCylindersErrorKeepsFallingBelowATenthOfAPercentFasterThanUniformRefinement) {
  // Issue 30, item 1 on api/examples/two_cylinders_gmsh.json (Gmsh triangles, non-matching; the steel's top pushed
  // down 0.05). With the stress indicator's marking the pressure error stalled at ~0.3 %: the far field, which
  // that marking leaves coarse, made the bodies 0.23 % too stiff. The goal-oriented marking of a target refines
  // what the pressure's error comes from. A target of 0.05 %: every step from 2 % down lowers the true error,
  // which ends below 0.1 %; the estimate follows it; and at the accuracy of every uniformly refined level of the
  // graded start, the adaptive run needs fewer unknowns (at the finest, a tenth).
  const json example_job = example("two_cylinders_gmsh.json");
  json job = example_job;
  job["adaptivity"] = {{"target_error", 0.0005}, {"max_steps", 30}};
  Estimates estimates;
  const Result r = run_to_target(job, estimates);
  ASSERT_TRUE(r.converged);
  ASSERT_EQ(estimates.pressure.size(), r.steps.size());
  // The reference: the run's last step (estimated 0.04 %; against an overkill of 3.9M unknowns, ~0.01 % from the
  // solution, it is 0.05 % off), read over 1.5 half-widths either side.
  const PairField& last = r.steps.back().pairs.at(0);
  const double R = 1.0 / (1.0 / 10 + 1.0 / 25), inv_E = (1 - 0.3 * 0.3) / 2.1e5 + (1 - 0.33 * 0.33) / 7.0e4;
  const double a = std::sqrt(4 * last.force * R * inv_E / M_PI);
  const PressureProfile reference(last);
  const auto error_of = [&](const Step& step) {
    return pressure_error(step.pairs.at(0), reference, -1.5 * a, 1.5 * a, 60000);
  };
  const auto dofs_of = mesh_unknowns;
  std::vector<double> errors;
  for (size_t k = 0; k < r.steps.size(); ++k) {
    errors.push_back(error_of(r.steps[k]));
    std::printf("  step %zu: %ld unknowns, estimate %.4f %%, error %.4f %%, effectivity %.2f\n", k, dofs_of(r.steps[k]),
                100 * estimates.pressure[k], 100 * errors[k], estimates.pressure[k] / errors[k]);
  }
  // No plateau: from 2 % down each step lowers the error, to below 0.1 % (read against a reference 0.05 % off,
  // the steps below 0.25 % are not compared).
  bool below_tenth = false;
  for (size_t k = 1; k + 1 < r.steps.size(); ++k) {
    if (errors[k - 1] < 0.02 && errors[k - 1] > 0.0025) EXPECT_LT(errors[k], errors[k - 1]) << "step " << k;
    // The estimate follows the error (measured 0.71 to 1.06 on the steps above 0.25 %).
    if (errors[k] > 0.0025) {
      EXPECT_GT(estimates.pressure[k], 0.6 * errors[k]) << "step " << k;
      EXPECT_LT(estimates.pressure[k], 2.5 * errors[k]) << "step " << k;
    }
    below_tenth = below_tenth || estimates.pressure[k] < 0.001;
  }
  EXPECT_TRUE(below_tenth);
  // Uniform refinement of the graded start, each level against the same reference; the adaptive run's first step
  // at or below each level's error has fewer unknowns (measured 2.9x at level 1, 11.7x at level 3, 23x at 4).
  const Result levels = uniform_levels(example_job, 4);
  ASSERT_TRUE(levels.converged) << levels.message;
  ASSERT_EQ(levels.steps.size(), 5u);
  for (size_t level = 1; level < levels.steps.size(); ++level) {
    const double e = error_of(levels.steps[level]);
    const long n = dofs_of(levels.steps[level]);
    size_t k = 0;
    while (k < errors.size() && errors[k] > e) ++k;
    ASSERT_LT(k, errors.size()) << "no adaptive step reaches uniform level " << level << "'s " << 100 * e << " %";
    std::printf("  uniform level %zu: %ld unknowns, error %.4f %%; adaptive step %zu: %ld unknowns (%.1fx)\n", level, n,
                100 * e, k, dofs_of(r.steps[k]), static_cast<double>(n) / dofs_of(r.steps[k]));
    EXPECT_LT(dofs_of(r.steps[k]), n) << "level " << level;
    if (level == 4) EXPECT_LE(10 * dofs_of(r.steps[k]), n);
  }
}

TEST(AdaptiveTarget, TheMonolithicMethodAdaptsWithoutAnEstimateAndRefusesATarget) {
  // The pressure estimate solves each body alone with its factorisation; the monolithic method builds one global
  // system and no body factorisations. Its adaptive runs used to end in "internal error: BodySolver::solve called
  // on a solver built without factorisation" once a step was estimated; now the estimate is not made there (NaN,
  // with a reason), and a target with that method is refused where the job names it.
  json job = example("hertz.json");
  ASSERT_EQ(job["solver"]["method"], "monolithic");
  job["adaptivity"] = {{"max_steps", 2}};
  job["output"] = {{"steps", "all"}};
  Estimates estimates;
  CancelToken cancel;
  const Result r = solve(parse_or_fail(job), estimates, cancel);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_EQ(r.steps.size(), 3u);
  for (const double e : estimates.pressure) EXPECT_TRUE(std::isnan(e));
  job["adaptivity"] = {{"target_error", 0.01}};
  EXPECT_NE(validation_errors(job).find("/adaptivity/target_error: target_error needs a domain-decomposition method"),
            std::string::npos)
      << validation_errors(job);
}

TEST(AdaptiveTarget, AMissedTargetIsSaidWithTheLastEstimateAndIsNotConverged) {
  // Two levels of refinement cannot reach 0.1 % from 8 x 2 cells: the run stops when nothing marked can be refined
  // and says the target was not reached, with the last step's estimate. That is not what the job asked for: not
  // converged (stagnation), every step it made kept, each converged (issue 51: it ended SUCCEEDED).
  json job = seed_layers_defaults(8);
  job["adaptivity"] = {{"target_error", 0.001}, {"max_level", 2}};
  Estimates estimates;
  CancelToken cancel;
  const Result r = solve(parse_or_fail(job), estimates, cancel);
  EXPECT_FALSE(r.converged) << r.message;
  EXPECT_EQ(r.stop_reason, StopReason::stagnation) << r.message;
  ASSERT_FALSE(r.steps.empty());
  EXPECT_TRUE(r.steps.back().converged);
  EXPECT_NE(r.message.find("the result keeps the"), std::string::npos) << r.message;
  // max_steps ends it before the meshes do: max_iterations.
  job["adaptivity"] = {{"target_error", 0.001}, {"max_steps", 1}};
  const Result short_run = solve(parse_or_fail(job), estimates, cancel);
  EXPECT_FALSE(short_run.converged) << short_run.message;
  EXPECT_EQ(short_run.stop_reason, StopReason::max_iterations) << short_run.message;
  ASSERT_FALSE(estimates.pressure.empty());
  EXPECT_GT(estimates.pressure.back(), 0.001);
  EXPECT_NE(r.message.find("target_error = 0.1 % not reached: the last step's estimated pressure error is"),
            std::string::npos)
      << r.message;
}

TEST(AdaptiveTarget, TheJobNamesATargetOnlyWhereTheEstimateCanBeMade) {
  json job = seed_layers_defaults(8);
  job["adaptivity"] = {{"target_error", 0.001}, {"indicator", "zz"}};
  EXPECT_NE(validation_errors(job).find("/adaptivity/target_error: target_error needs the fem_bem indicator"),
            std::string::npos)
      << validation_errors(job);
  job["adaptivity"] = {{"target_error", 0}};
  EXPECT_NE(validation_errors(job).find("/adaptivity/target_error: target_error must lie in (0, 1)"), std::string::npos)
      << validation_errors(job);
  job["adaptivity"] = {{"target_error", "0.1 %"}};
  EXPECT_NE(validation_errors(job).find("/adaptivity/target_error"), std::string::npos) << validation_errors(job);
  // With a target the stop test on the changes is off unless the job sets it.
  job["adaptivity"] = {{"target_error", 0.002}};
  const auto parsed = job::parse(job);
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  EXPECT_EQ(parsed.problem->adaptivity.stop_tolerance, 0.0);
  EXPECT_EQ(parsed.problem->normalized["adaptivity"]["stop_tolerance"], 0.0);
  EXPECT_EQ(parsed.problem->adaptivity.target_error, 0.002);
  job["adaptivity"]["stop_tolerance"] = 0.01;
  EXPECT_EQ(job::parse(job).problem->adaptivity.stop_tolerance, 0.01);
  // And max_level is 12 (the contact edges' share of the error falls with their cells) and max_steps 30, unless
  // the job sets them. Without a target max_level stays 8 (a singular peak, a punch's corner, would take the goal
  // marking to the limit), max_steps is 30 under the default marking ("goal", which refines as a target does) and 20
  // under the indicator's marking (a delta given).
  EXPECT_EQ(parsed.problem->adaptivity.max_level, 12);
  EXPECT_EQ(parsed.problem->normalized["adaptivity"]["max_level"], 12);
  EXPECT_EQ(parsed.problem->adaptivity.max_steps, 30);
  job["adaptivity"]["max_level"] = 6;
  job["adaptivity"]["max_steps"] = 7;
  EXPECT_EQ(job::parse(job).problem->adaptivity.max_level, 6);
  EXPECT_EQ(job::parse(job).problem->adaptivity.max_steps, 7);
  job["adaptivity"] = json::object();
  EXPECT_EQ(job::parse(job).problem->adaptivity.marking, MarkingRule::goal);
  EXPECT_EQ(job::parse(job).problem->adaptivity.max_level, 8);
  EXPECT_EQ(job::parse(job).problem->adaptivity.max_steps, 30);
  job["adaptivity"] = {{"delta", 0.1}};
  EXPECT_EQ(job::parse(job).problem->adaptivity.marking, MarkingRule::contact);
  EXPECT_EQ(job::parse(job).problem->adaptivity.max_level, 8);
  EXPECT_EQ(job::parse(job).problem->adaptivity.max_steps, 20);
}
