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
  const std::vector<Eigen::VectorXd>* warm_start = nullptr;  // start of the iterative methods, if given
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

struct MethodOutcome {
  Displacements u;  // final displacements per body
  bool converged = false;
  StopReason reason = StopReason::error;
  std::string message;
  int iterations = 0;
  double gamma = 0.0;
  int solves_per_body = 0;  // subdomain solves (back-substitutions) per body, initial guess included
  double indicator_seconds = 0.0;  // adaptivity: time spent estimating (BEM solves and evaluations)
  std::vector<IterationReport> history;
};

// The paper's parallel Neumann scheme (16)-(17) on fixed meshes.
MethodOutcome run_neumann(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

// The Robin-type variant (ALGORITHM.md): each body's matrix carries the Robin weight on its contact zone.
MethodOutcome run_robin(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

// Each body's contact-zone compliance by blocked back-substitutions (in parallel), semismooth Newton on the
// small interface problem, one final solve per body.
MethodOutcome run_interface_newton(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

// The same discrete penalty problem solved in one system by a semismooth Newton method (reference solver).
MethodOutcome run_monolithic(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

}  // namespace contact::ddm
