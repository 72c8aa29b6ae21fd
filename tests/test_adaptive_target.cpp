// Issue 30, item 2: an adaptive run that stops at the accuracy the job asks for (adaptivity.target_error), with
// an estimate of the contact pressure's error (solver/adapt/pressure_estimate.hpp) checked against the true error
// of the paper's test, measured against an independent overkill solution.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "adaptive_support.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

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
  json overkill = seed_layers_defaults(8);
  overkill["adaptivity"] = {{"delta", 0.01}, {"max_level", 11}, {"stop_tolerance", 0}, {"max_steps", 9}};
  const Result fine = run(overkill);
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
  job["output"] = {{"steps", "all"}};
  Estimates estimates;
  CancelToken cancel;
  const Result r = solve(parse_or_fail(job), estimates, cancel);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_NE(r.message.find("target met after"), std::string::npos) << r.message;
  ASSERT_EQ(estimates.pressure.size(), r.steps.size());
  // It stops at the first step whose estimate meets the target.
  for (size_t k = 0; k + 1 < r.steps.size(); ++k) EXPECT_GT(estimates.pressure[k], 0.001) << "step " << k;
  EXPECT_LE(estimates.pressure.back(), 0.001);
  // The estimate is the error: effectivity (estimate / true error) between 0.8 and 2.5 at every step whose error
  // is well above the reference's own (measured: 1.04 to 1.9).
  for (size_t k = 0; k < r.steps.size(); ++k) {
    const double error = pressure_error(r.steps[k].pairs.at(0), reference);
    std::printf("  step %zu: %ld unknowns, estimate %.4f %%, error %.4f %%, effectivity %.2f\n", k,
                unknowns(r, r.steps[k].iteration), 100 * estimates.pressure[k], 100 * error,
                estimates.pressure[k] / error);
    if (error > 0.0005) {
      EXPECT_GT(estimates.pressure[k], 0.8 * error) << "step " << k;
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

TEST(AdaptiveTarget, AMissedTargetIsSaidWithTheLastEstimate) {
  // Two levels of refinement cannot reach 0.1 % from 8 x 2 cells: the run stops when nothing marked can be refined
  // and says the target was not reached, with the last step's estimate.
  json job = seed_layers_defaults(8);
  job["adaptivity"] = {{"target_error", 0.001}, {"max_level", 2}};
  Estimates estimates;
  CancelToken cancel;
  const Result r = solve(parse_or_fail(job), estimates, cancel);
  ASSERT_TRUE(r.converged) << r.message;
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
  EXPECT_NE(validation_errors(job).find("/adaptivity/target_error: target_error must lie in (0, 1)"),
            std::string::npos)
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
}
