// What every contact method (Neumann DDM, monolithic reference, and the methods still to come) takes and
// returns, so that solve() only dispatches.
#pragma once

#include "../result.hpp"
#include "contact_system.hpp"

#include <chrono>
#include <string>
#include <vector>

namespace contact::ddm {

struct RunContext {
  Observer& observer;
  const CancelToken& cancel;
  TaskRunner& runner;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

struct MethodOutcome {
  Displacements u;  // final displacements per body
  bool converged = false;
  StopReason reason = StopReason::error;
  std::string message;
  int iterations = 0;
  double gamma = 0.0;
  std::vector<IterationReport> history;
};

// The paper's parallel Neumann scheme (16)-(17) on fixed meshes.
MethodOutcome run_neumann(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

// The same discrete penalty problem solved in one system by a semismooth Newton method (reference solver).
MethodOutcome run_monolithic(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

}  // namespace contact::ddm
