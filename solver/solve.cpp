#include "solve.hpp"

#include "ddm/method.hpp"

#include <chrono>
#include <exception>

namespace contact {

const char* solver_version() { return CONTACT_VERSION; }

Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel) {
  const auto start = std::chrono::steady_clock::now();
  Result result;
  result.method = problem.solver.method == Method::monolithic ? "monolithic" : "neumann";
  try {
    ddm::ThreadTaskRunner runner(ddm::choose_threads(problem.solver.threads, problem.bodies.size()));
    // The monolithic reference factorises the coupled system itself; the DDM factorises each body once.
    const bool per_body_factorization = problem.solver.method != Method::monolithic;
    ddm::ContactSystem system(problem, runner, per_body_factorization);
    result.setup_seconds = system.setup_seconds();
    result.factorization_seconds = system.factorization_seconds();
    if (!system.ok()) {
      result.stop_reason = StopReason::error;
      result.message = system.error();
      result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return result;
    }
    ddm::RunContext context{observer, cancel, runner, start};
    ddm::MethodOutcome outcome = problem.solver.method == Method::monolithic
                                     ? ddm::run_monolithic(system, problem.solver, context)
                                     : ddm::run_neumann(system, problem.solver, context);
    result.converged = outcome.converged;
    result.stop_reason = outcome.reason;
    result.message = outcome.message;
    result.iterations = outcome.iterations;
    result.gamma = outcome.gamma;
    result.history = std::move(outcome.history);
    result.steps.push_back(system.fields(outcome.u, outcome.iterations));
  } catch (const std::exception& e) {
    result.stop_reason = StopReason::error;
    result.message = std::string("internal error: ") + e.what();
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace contact
