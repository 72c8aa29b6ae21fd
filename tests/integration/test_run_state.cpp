// The run's state (ddm/run_state.hpp: the load point, friction's slip origins, the augmented-Lagrangian multipliers)
// lives beside the ContactSystem, in the run's frame, not in the system: a system solved twice, each time in a frame
// of its own, gives the same answer bit for bit, and the same answer as solve() on a system of its own. (When the
// slip origins and the multipliers were written into the pairs, a second run started from where the first ended.)
#include "ddm/load_steps.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

using namespace contact;
using contact::testing::example;
using contact::testing::parse_or_fail;
using contact::testing::solve_quietly;

namespace {

// The load path of `problem` solved on `system` in a frame (and a run state) of its own; the steps it keeps.
std::vector<Step> solve_on(const ddm::ContactSystem& system, const Problem& problem) {
  Observer quiet;
  CancelToken cancel;
  parallel::ThreadTaskRunner runner(1);
  ddm::RunFrame frame(problem.solver, quiet, cancel, runner);
  const std::unique_ptr<ddm::ContactMethod> method = ddm::make_method(system, problem.solver.method);
  ddm::StepLog steps(StepOutput::all);
  ddm::run_load_steps(system, problem.loading.factors, frame, *method, steps);
  EXPECT_TRUE(frame.outcome().converged) << frame.outcome().message;
  return steps.take_steps();
}

void expect_identical(const std::vector<Step>& a, const std::vector<Step>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t s = 0; s < a.size(); ++s) {
    EXPECT_EQ(a[s].load_factor, b[s].load_factor) << what << ", step " << s;
    ASSERT_EQ(a[s].bodies.size(), b[s].bodies.size());
    for (size_t k = 0; k < a[s].bodies.size(); ++k)
      EXPECT_EQ(a[s].bodies[k].displacement, b[s].bodies[k].displacement)
          << what << ", step " << s << ", body " << a[s].bodies[k].name;
    ASSERT_EQ(a[s].pairs.size(), b[s].pairs.size());
    for (size_t k = 0; k < a[s].pairs.size(); ++k) {
      EXPECT_EQ(a[s].pairs[k].pressure, b[s].pairs[k].pressure) << what << ", step " << s << ", pair " << k;
      EXPECT_EQ(a[s].pairs[k].tangential_traction, b[s].pairs[k].tangential_traction)
          << what << ", step " << s << ", pair " << k;
    }
  }
}

// Both runs on one system, then solve() (its own system) as the reference.
void expect_runs_independent(const Problem& problem) {
  parallel::ThreadTaskRunner runner(1);
  const ddm::ContactSystem system(problem, runner, ddm::facts_of(problem.solver.method).factorization);
  ASSERT_TRUE(system.ok()) << system.error();
  const std::vector<Step> first = solve_on(system, problem);
  const std::vector<Step> second = solve_on(system, problem);
  ASSERT_EQ(first.size(), problem.loading.factors.size());
  expect_identical(first, second, "the second run on one system");
  Problem one_thread = problem;
  one_thread.solver.threads = 1;
  one_thread.output.steps = StepOutput::all;
  const Result reference = solve_quietly(one_thread);
  ASSERT_TRUE(reference.converged) << reference.message;
  expect_identical(first, reference.steps, "solve() on a system of its own");
}

}  // namespace

// Friction: each step's slip is measured from the previous step's end (the slip origins), and two of the roller's
// loads have histories of their own (the load point's step matters, not only its factor).
TEST(RunState, AFrictionalLoadPathSolvedTwiceOnOneSystemGivesTheSameAnswer) {
  Problem problem = parse_or_fail(example("roller_friction.json"));
  expect_runs_independent(problem);
}

// The augmented Lagrangian's multipliers, carried from one load step to the next within a run, not across runs.
TEST(RunState, AugmentedLagrangianStepsSolvedTwiceOnOneSystemGiveTheSameAnswer) {
  nlohmann::json job = example("seed_layers_steps.json");
  job["loading"] = {{"steps", 3}};
  job["solver"]["enforcement"] = "augmented_lagrangian";
  expect_runs_independent(parse_or_fail(job));
}

// A rebuild rediscretises the pairs: the state's per-pair values (of the old pairs) are dropped with them; the load
// point is the run's and stays.
TEST(RunState, ARebuildDropsThePerPairValuesAndKeepsTheLoadPoint) {
  const Problem problem = parse_or_fail(example("roller_friction.json"));
  parallel::ThreadTaskRunner runner(1);
  ddm::ContactSystem system(problem, runner, ddm::ContactSystem::Factorization::interface);
  ASSERT_TRUE(system.ok()) << system.error();
  ddm::RunState state;
  state.load = fem::LoadPoint{2, 1.0, 1.0, 0.5};
  ddm::Displacements u(system.n_bodies());
  for (size_t a = 0; a < u.size(); ++a) u[a] = Eigen::VectorXd::Constant(system.body(a).n_dofs(), 1e-3 * (a + 1.0));
  state.slip_origin = system.tangential_jumps(u);
  state.multipliers.assign(system.pairs().size(), Eigen::VectorXd::Ones(system.pairs()[0].n_rows()));
  ASSERT_NE(state.slip_origin_of(0, system.pairs()[0].n_rows()), nullptr);
  system.rebuild(std::vector<char>(system.n_bodies(), 0), state);
  ASSERT_TRUE(system.ok()) << system.error();
  EXPECT_TRUE(state.slip_origin.empty());
  EXPECT_TRUE(state.multipliers.empty());
  EXPECT_EQ(state.load.step, 2u);
  EXPECT_EQ(state.load.t, 0.5);
}

// The load point: a history's own factor interpolated within a cut step, the loading's factor elsewhere.
TEST(RunState, ALoadPointInterpolatesTheLoadingAndEachHistoryWithinAStep) {
  const fem::LoadPoint at{1, 0.5, 1.5, 0.25};
  EXPECT_DOUBLE_EQ(at.value(), 0.75);
  EXPECT_DOUBLE_EQ(at.of_history({}), 0.75);
  EXPECT_DOUBLE_EQ(at.of_history({0.0, 2.0}), 0.5);  // from 0 at the end of step 0 to 2 at the end of step 1
  EXPECT_DOUBLE_EQ(at.of_history({4.0}), 4.0);       // the last value repeated
  EXPECT_DOUBLE_EQ(fem::LoadPoint::end_of(0, 0.3).of_history({0.7, 1.0}), 0.7);
  EXPECT_DOUBLE_EQ(fem::LoadPoint{}.value(), 1.0);
}
