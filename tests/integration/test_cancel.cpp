// Cancellation inside the steps that cannot poll a token themselves: a body's assembly (polled between cells) and
// its CHOLMOD factorisation (run on a thread of its own that the solve abandons, common/background.hpp).
#include "support.hpp"

#include "fem/body_solver.hpp"

#include <atomic>
#include <functional>
#include <chrono>
#include <cstdio>
#include <future>
#include <thread>

namespace contact::testing {
namespace {

// The paper's two layers on fine uniform meshes: each body's factorisation takes seconds.
nlohmann::json large_layers(int nx, int ny) {
  nlohmann::json job = example("seed_layers.json");
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = nx;
    b["mesh"]["block"]["ny"] = ny;
  }
  job["solver"] = nlohmann::json::object();  // the defaults: interface Newton, exact contact
  return job;
}

using Seconds = std::chrono::duration<double>;

// What a cancel stops is checked (no poll after it, the factorisation left running, nothing solved); its latency is
// printed. The only bound on it, a hundred times the usual fraction of a second, catches a hang, not a loaded
// machine (tests run on loaded 2-core machines).
constexpr double kHangSeconds = 30.0;

TEST(CancelDuringSetUp, ACancelInsideAFactorisationReturnsWithinAPollAndTheFactorisationEndsAlone) {
  // The paper's upper layer, 1024 x 128 cells (~260k unknowns): its assembly polls once per 8192 cells (17 polls),
  // the factorisation's wait once at its start and then every 20 ms; the test says "cancelled" from the 6th poll
  // of the factorisation on, ~0.1 s into it (a factorisation of that size takes a second or more).
  const Problem problem = parse_or_fail(large_layers(1024, 128));
  ASSERT_FALSE(problem.bodies.empty());
  const int assembly_polls = (problem.bodies[0].mesh.num_cells() + 8191) / 8192;
  std::atomic<int> polls{0};
  std::chrono::steady_clock::time_point tripped;
  std::function<bool()> cancelled = [&] {
    if (++polls < assembly_polls + 6) return false;
    if (polls == assembly_polls + 6) tripped = std::chrono::steady_clock::now();
    return true;
  };
  const fem::BodySolver body(problem.bodies[0], problem.model, true, {}, false, true, cancelled);
  const double latency = Seconds(std::chrono::steady_clock::now() - tripped).count();
  const bool abandoned = background_work_running();
  std::printf("  returned %.3f s after the cancel\n", latency);
  EXPECT_TRUE(wait_for_background_work(120)) << "the abandoned factorisation did not end";
  EXPECT_EQ(polls.load(), assembly_polls + 6) << "polled after the cancel";
  EXPECT_TRUE(body.was_cancelled());
  EXPECT_FALSE(body.ok());
  EXPECT_NE(body.error().find("body 'upper': cancelled during the factorisation"), std::string::npos) << body.error();
  EXPECT_LE(latency, kHangSeconds);
  // Returned while the factorisation still ran: it did not wait for it.
  EXPECT_TRUE(abandoned) << "the factorisation had ended before the cancel: the test measured nothing";
}

TEST(CancelDuringSetUp, ACancelDuringTheSetUpStopsTheSolveThereWithNothingSolved) {
  const Problem problem = parse_or_fail(large_layers(1024, 128));  // two bodies of ~260k unknowns
  ASSERT_FALSE(problem.bodies.empty());
  Observer quiet;
  CancelToken cancel;
  auto solving = std::async(std::launch::async, [&] { return solve(problem, quiet, cancel); });
  // Inside the assembly or the factorisations (a second or more in all): either must stop the solve there.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto cancelled_at = std::chrono::steady_clock::now();
  cancel.cancel();
  const Result r = solving.get();
  const double latency = Seconds(std::chrono::steady_clock::now() - cancelled_at).count();
  std::printf("  the solve returned %.3f s after the cancel\n", latency);
  EXPECT_TRUE(wait_for_background_work(120)) << "the abandoned factorisations did not end";
  EXPECT_EQ(r.stop_reason, StopReason::cancelled) << r.message;
  EXPECT_NE(r.message.find("cancelled during the set-up"), std::string::npos) << r.message;
  EXPECT_TRUE(r.steps.empty());
  EXPECT_LE(latency, kHangSeconds);
}

TEST(CancelDuringSetUp, ACancelBeforeTheSolveStartsBuildsNothing) {
  const Problem problem = parse_or_fail(large_layers(64, 16));
  Observer quiet;
  CancelToken cancel;
  cancel.cancel();
  const Result r = solve(problem, quiet, cancel);
  EXPECT_EQ(r.stop_reason, StopReason::cancelled) << r.message;
  EXPECT_FALSE(background_work_running());
}

TEST(CancelDuringSetUp, WithoutACancelTheSameSolveConvergesAndLeavesNothingRunning) {
  const Result r = run(large_layers(64, 16));
  EXPECT_EQ(r.stop_reason, StopReason::converged) << r.message;
  EXPECT_FALSE(background_work_running());
}

}  // namespace
}  // namespace contact::testing
