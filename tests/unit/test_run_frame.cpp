// The run frame's nesting (ddm/run_frame.hpp), what every nested loop runs its inner solves in: inner solves'
// iterations run on, their reports are marked, their work adds up and the last one's answer and stop are the total's.
#include "ddm/run_frame.hpp"

#include <gtest/gtest.h>

using namespace contact;

namespace {

struct Recorder : Observer {
  std::vector<IterationReport> reports;
  void on_iteration(const IterationReport& r) override { reports.push_back(r); }
};

// An inner solve of `iterations` iterations, reporting each with one body, as a method does.
void inner_solve(ddm::RunFrame& frame, int iterations, int solves, StopReason reason, const std::string& solver) {
  ddm::MethodOutcome& out = frame.outcome();
  for (int k = 1; k <= iterations; ++k) {
    IterationReport r;
    r.iteration = k;
    r.bodies.assign(1, BodyReport{});
    frame.report(r);
  }
  out.iterations = iterations;
  out.updates = 1;
  out.subdomain_solves = solves;
  out.interface_iterations = 10 * solves;
  out.interface_solver = solver;
  out.u.assign(1, Eigen::VectorXd::Constant(2, iterations));
  out.converged = reason == StopReason::converged;
  out.stop_reason = reason;
  out.message = "inner " + std::to_string(iterations);
}

}  // namespace

TEST(RunFrame, InnerIterationsRunOnMarkedAndTheWorkAddsUp) {
  Recorder recorder;
  CancelToken cancel;
  parallel::ThreadTaskRunner runner(1);
  const SolverSettings settings;
  ddm::RunFrame frame(settings, recorder, cancel, runner);
  frame.nested(nullptr, ddm::InnerMarks{1, {7}},
               [](ddm::RunFrame& inner) { inner_solve(inner, 2, 3, StopReason::converged, "direct"); });
  const ddm::MethodOutcome& t =
      frame.nested(nullptr, ddm::InnerMarks{2, {}},
                   [](ddm::RunFrame& inner) { inner_solve(inner, 3, 4, StopReason::max_iterations, ""); });

  // Iterations 1..5 across the two solves, in the observer's reports and in the history alike.
  ASSERT_EQ(recorder.reports.size(), 5u);
  ASSERT_EQ(t.history.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(recorder.reports[static_cast<size_t>(k)].iteration, k + 1);
    EXPECT_EQ(t.history[static_cast<size_t>(k)].iteration, k + 1);
    const int update = k < 2 ? 1 : 2;
    EXPECT_EQ(recorder.reports[static_cast<size_t>(k)].update, update);
    EXPECT_EQ(t.history[static_cast<size_t>(k)].update, update);
    // The refined counts mark the first report of the first solve only.
    const int refined = k == 0 ? 7 : 0;
    EXPECT_EQ(recorder.reports[static_cast<size_t>(k)].bodies[0].elements_refined, refined);
    EXPECT_EQ(t.history[static_cast<size_t>(k)].bodies[0].elements_refined, refined);
  }
  EXPECT_EQ(t.iterations, 5);
  EXPECT_EQ(t.updates, 2);
  EXPECT_EQ(t.subdomain_solves, 7);
  EXPECT_EQ(t.interface_iterations, 70);
  EXPECT_EQ(t.interface_solver, "direct");  // an inner solve that names none keeps the last one named
  // The last solve's answer and stop.
  EXPECT_EQ(t.u[0][0], 3.0);
  EXPECT_FALSE(t.converged);
  EXPECT_EQ(t.stop_reason, StopReason::max_iterations);
  EXPECT_EQ(t.message, "inner 3");
}
