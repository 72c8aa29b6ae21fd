// What every contact method (interface Newton, Neumann DDM, Robin, monolithic reference) takes and returns, and
// the one interface they share (ContactMethod, made by make_method), so that the outer loops (augmented
// Lagrangian, load steps, adaptivity) and solve() know no method by name.
#pragma once

#include "contact/result.hpp"
#include "contact_system.hpp"

#include <chrono>
#include <memory>
#include <string>
#include <vector>

namespace contact::ddm {

struct RunContext {
  Observer& observer;
  const CancelToken& cancel;
  parallel::TaskRunner& runner;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  const std::vector<Eigen::VectorXd>* warm_start = nullptr;  // start of the iterative methods, if given
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

struct MethodOutcome {
  Displacements u;  // final displacements per body
  Pressures z;      // final contact pressures per pair, where they are not the penalty pressures of u (exact)
  Pressures q;      // friction: final tangential multipliers per pair (empty: frictionless; mortar/pair.hpp)
  std::vector<Eigen::VectorXd> rigid_amplitudes;  // per body: floating bodies' rigid-mode amplitudes (else empty)
  bool converged = false;
  StopReason reason = StopReason::error;
  std::string message;
  // Refused before any solve (statics: friction cannot hold the loads, ddm/friction_statics.hpp; or the settings):
  // a smaller increment of the same step would be refused too (load_steps.cpp cuts only the other failures).
  bool refused = false;
  int iterations = 0;
  int updates = 0;  // augmented-Lagrangian updates (0 for the penalty or exact problem alone)
  double gamma = 0.0;
  int solves_per_body = 0;  // subdomain solves (back-substitutions) per body, initial guess included
  double indicator_seconds = 0.0;  // adaptivity: time spent estimating (BEM solves and evaluations)
  std::string interface_solver;    // interface_newton: "direct" or "iterative" (the last one used)
  long interface_iterations = 0;   // the iterative interface solver's products with the interface operator
  std::vector<IterationReport> history;
};

// A contact method on a ContactSystem: run() solves once on the pairs' current gaps (and augmented-Lagrangian
// multipliers); without contact pairs every method's answer is each body solved once, which run() gives for all.
// A method may keep what it built for the system between runs (interface Newton: its interface problem); reset()
// forgets it after the meshes changed. A new method is a class here and a case in make_method (method.cpp).
class ContactMethod {
 public:
  ContactMethod(const ContactSystem& system, const SolverSettings& settings) : system_(system), settings_(settings) {}
  virtual ~ContactMethod() = default;
  ContactMethod(const ContactMethod&) = delete;
  ContactMethod& operator=(const ContactMethod&) = delete;

  MethodOutcome run(RunContext& context);
  virtual void reset() {}

 protected:
  virtual MethodOutcome solve(RunContext& context) = 0;
  const ContactSystem& system_;
  const SolverSettings& settings_;
};

std::unique_ptr<ContactMethod> make_method(const ContactSystem& system, const SolverSettings& settings);

// The paper's parallel Neumann scheme (16)-(17) on fixed meshes.
MethodOutcome run_neumann(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

// The Robin-type variant (docs/algorithm.md): each body's matrix carries the Robin weight on its contact zone.
MethodOutcome run_robin(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

// The same discrete problem (exact or penalty, per the settings' enforcement) solved in one system: the
// reference solver (monolithic.cpp).
MethodOutcome run_monolithic(const ContactSystem& system, const SolverSettings& settings, RunContext& context);

}  // namespace contact::ddm
