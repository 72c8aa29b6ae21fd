// The interfaces the server plugs into: one report per iteration, in order, with the documented fields; and
// cancellation within one iteration.
#include "contact/job.hpp"
#include "contact/solve.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <fstream>

using namespace contact;

namespace {

Problem seed(const std::string& method) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers.json");
  nlohmann::json job = nlohmann::json::parse(in);
  job["solver"]["method"] = method;
  job["solver"]["criterion"] = "residual";
  job["solver"]["tolerance"] = 1e-9;
  job["solver"]["gamma"] = 0.05;
  job["solver"]["acceleration"] = "none";
  job["solver"]["enforcement"] = "penalty";
  auto r = job::parse(job);
  EXPECT_TRUE(r.ok()) << job::format_errors(r.errors);
  return std::move(*r.problem);
}

struct Recorder : Observer {
  std::vector<IterationReport> reports;
  CancelToken* cancel_at_two = nullptr;
  void on_iteration(const IterationReport& r) override {
    reports.push_back(r);
    if (cancel_at_two && r.iteration == 2) cancel_at_two->cancel();
  }
};

}  // namespace

// Issue 32, item 6: the roller example with its base contact frictionless has no equilibrium once the plate is
// pushed sideways; its solve stopped at max_iterations on an iterate whose base contact pulled (force -3865), and
// the server called that SUCCEEDED. The solve says it did not converge, and a pulling contact in its last
// iterate is named as no answer (a contact only pushes).
TEST(Outcome, AnIterateThatPullsAtAContactIsSaidToBeNoAnswer) {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/roller_friction.json");
  nlohmann::json job = nlohmann::json::parse(in);
  job["contacts"][0].erase("friction");
  job["output"] = {{"iterate", true}};  // the iterate it stops on is kept, to be judged
  auto parsed = job::parse(job);
  ASSERT_TRUE(parsed.ok()) << job::format_errors(parsed.errors);
  Recorder recorder;
  CancelToken cancel;
  const Result result = solve(*parsed.problem, recorder, cancel);
  EXPECT_FALSE(result.converged) << result.message;
  EXPECT_NE(result.stop_reason, StopReason::converged) << result.message;
  if (result.steps.empty()) {  // refused as an error (e.g. nothing holds the bodies): no iterate to judge
    EXPECT_EQ(result.stop_reason, StopReason::error) << result.message;
    return;
  }
  // A pair pulls beyond rounding when its force is below -1e-6 of the largest sum of |weight x pressure| over the
  // step's pairs (solve.cpp, tensile_pairs): a force of -0.0016 against thousands is the rounding of a contact
  // that carries nothing, not a pull.
  double scale = 0.0;
  for (const auto& pair : result.steps.back().pairs)
    scale = std::max(scale, pair.weight.cwiseProduct(pair.pressure).cwiseAbs().sum());
  for (const auto& pair : result.steps.back().pairs)
    if (pair.force < -1e-6 * scale)
      EXPECT_NE(result.message.find("the last iterate is not an answer: contact '" + pair.name + "'"),
                std::string::npos)
          << pair.name << " pulls with " << pair.force << " (scale " << scale << "): " << result.message;
}

TEST(Observer, ReceivesEveryIterationInOrderWithTheDocumentedFields) {
  for (const char* method : {"neumann", "monolithic"}) {
    const Problem p = seed(method);
    Recorder rec;
    CancelToken cancel;
    const Result r = solve(p, rec, cancel);
    ASSERT_TRUE(r.converged) << method << ": " << r.message;
    ASSERT_EQ(static_cast<int>(rec.reports.size()), r.iterations) << method;
    ASSERT_EQ(r.history.size(), rec.reports.size());
    double last_elapsed = 0;
    for (size_t i = 0; i < rec.reports.size(); ++i) {
      const auto& rep = rec.reports[i];
      EXPECT_EQ(rep.iteration, static_cast<int>(i) + 1);
      EXPECT_GE(rep.elapsed_seconds, last_elapsed);
      last_elapsed = rep.elapsed_seconds;
      ASSERT_EQ(rep.bodies.size(), 2u);
      EXPECT_EQ(rep.bodies[0].name, "upper");
      EXPECT_EQ(rep.bodies[0].elements, 32 * 8);
      EXPECT_GT(rep.bodies[0].dofs, 0);
      ASSERT_EQ(rep.pairs.size(), 1u);
      EXPECT_EQ(rep.pairs[0].positions.size(), rep.pairs[0].pressures.size());
      EXPECT_EQ(rep.pairs[0].positions.size(), 33u);
      EXPECT_GT(rep.pairs[0].theta, 0.0);
    }
    const auto& last = rec.reports.back();
    EXPECT_NEAR(last.pairs[0].force, r.steps.back().pairs[0].force, 1e-12 * last.pairs[0].force);
    EXPECT_GT(last.pairs[0].active_nodes, 0);
    EXPECT_GT(last.pairs[0].extent_end, 0.7);  // contact reaches about x = 1
    EXPECT_LT(last.pairs[0].extent_end, 1.3);
    if (std::string(method) == "neumann") EXPECT_LE(last.fixed_point_residual, 1e-9);
  }
}

TEST(Cancellation, ARunningSolveStopsWithinOneIteration) {
  for (const char* method : {"neumann", "monolithic"}) {
    const Problem p = seed(method);
    Recorder rec;
    CancelToken cancel;
    rec.cancel_at_two = &cancel;
    const Result r = solve(p, rec, cancel);
    EXPECT_EQ(r.stop_reason, StopReason::cancelled) << method;
    EXPECT_FALSE(r.converged);
    EXPECT_EQ(r.iterations, 2) << method;
    EXPECT_EQ(rec.reports.size(), 2u);
    EXPECT_TRUE(r.steps.empty()) << "an iterate is kept only if asked for";
  }
  for (const char* method : {"neumann", "monolithic"}) {
    Problem p = seed(method);
    p.output.iterate = true;
    Recorder rec;
    CancelToken cancel;
    rec.cancel_at_two = &cancel;
    const Result r = solve(p, rec, cancel);
    EXPECT_EQ(r.stop_reason, StopReason::cancelled) << method;
    ASSERT_EQ(r.steps.size(), 1u) << "the state reached, asked for (output.iterate)";
    EXPECT_FALSE(r.steps[0].converged);
  }
}

TEST(Cancellation, ACancelledTokenStopsBeforeTheFirstIteration) {
  const Problem p = seed("neumann");
  Recorder rec;
  CancelToken cancel;
  cancel.cancel();
  const Result r = solve(p, rec, cancel);
  EXPECT_EQ(r.stop_reason, StopReason::cancelled);
  EXPECT_TRUE(rec.reports.empty());
}

TEST(Divergence, TooLargeGammaIsStoppedEarlyWithAMessageNamingGamma) {
  Problem p = seed("neumann");
  p.solver.gamma = 1.0;  // far above the stability bound (about 0.067 here)
  p.solver.max_iterations = 500;
  Observer quiet;
  CancelToken cancel;
  const Result r = solve(p, quiet, cancel);
  // gamma = 1 locks the penalty into an on/off cycle: stagnation, reported long before max_iterations.
  EXPECT_TRUE(r.stop_reason == StopReason::stagnation || r.stop_reason == StopReason::error) << r.message;
  EXPECT_LT(r.iterations, 200);
  EXPECT_NE(r.message.find("gamma"), std::string::npos) << r.message;
  // A gamma far above the bound whose iterates do grow is reported as divergence, not as NaNs.
  // Its iterate, asked for (output.iterate), holds no NaN; not asked for, it is left out.
  p.solver.gamma = 1.9;
  p.solver.initial_guess = InitialGuess::zero;
  const Result left_out = solve(p, quiet, cancel);
  EXPECT_NE(left_out.stop_reason, StopReason::converged);
  EXPECT_TRUE(left_out.steps.empty());
  p.output.iterate = true;
  const Result d = solve(p, quiet, cancel);
  EXPECT_NE(d.stop_reason, StopReason::converged);
  EXPECT_NE(d.message.find("gamma"), std::string::npos) << d.message;
  ASSERT_FALSE(d.steps.empty()) << d.message;
  for (const auto& pair : d.steps.back().pairs) EXPECT_TRUE(std::isfinite(pair.force));
}

TEST(Parallelism, BodiesFactorisedAndSolvedConcurrentlyGiveTheSequentialAnswer) {
  // Large enough for CHOLMOD's supernodal (BLAS) path: with a BLAS unsafe for concurrent callers (Debian's
  // serial OpenBLAS) the two factorisations corrupt each other. See solver/fem/blas_threads.hpp.
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers.json");
  nlohmann::json job = nlohmann::json::parse(in);
  for (auto& body : job["bodies"]) {
    body["mesh"]["block"]["nx"] = 320;
    body["mesh"]["block"]["ny"] = 80;
  }
  job["solver"]["max_iterations"] = 3;
  job["output"] = {{"iterate", true}};  // the iterates after 3 iterations are compared
  Result results[2];
  for (int threads : {1, 2}) {
    job["solver"]["threads"] = threads;
    auto parsed = job::parse(job);
    ASSERT_TRUE(parsed.ok());
    Observer quiet;
    CancelToken cancel;
    results[threads - 1] = solve(*parsed.problem, quiet, cancel);
    ASSERT_FALSE(results[threads - 1].steps.empty()) << results[threads - 1].message;
    ASSERT_NE(results[threads - 1].stop_reason, StopReason::error) << results[threads - 1].message;
  }
  for (size_t b = 0; b < 2; ++b) {
    const auto& u1 = results[0].steps.back().bodies[b].displacement;
    const auto& u2 = results[1].steps.back().bodies[b].displacement;
    EXPECT_LE((u1 - u2).cwiseAbs().maxCoeff(), 1e-12 * u1.cwiseAbs().maxCoeff());
  }
}
