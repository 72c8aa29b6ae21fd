// Runs one contact method, with or without augmented-Lagrangian updates, on a ContactSystem: the dispatch
// shared by solve() and the adaptive loop.
#pragma once

#include "interface/interface_newton.hpp"
#include "method.hpp"

#include <memory>

namespace contact::ddm {

// Passes reports on with iteration numbers shifted by `offset`, the augmented-Lagrangian update set to `update`
// (if > 0) and, on the first report only, the given per-body counts of refined elements.
class OffsetObserver final : public Observer {
 public:
  OffsetObserver(Observer& inner, int offset, int update = 0, std::vector<int> refined = {})
      : inner_(inner), offset_(offset), update_(update), refined_(std::move(refined)) {}
  void on_iteration(const IterationReport& r) override;

 private:
  Observer& inner_;
  int offset_, update_;
  std::vector<int> refined_;
};

// Runs the chosen method once on the pairs' current (possibly multiplier-shifted) gaps. Keeps interface
// Newton's interface problem between calls; reset() forgets it (after the meshes changed).
class MethodRunner {
 public:
  MethodRunner(const ContactSystem& system, const SolverSettings& settings) : system_(system), settings_(settings) {}
  MethodOutcome run(RunContext& context);
  void reset() { interface_newton_.reset(); }

 private:
  const ContactSystem& system_;
  const SolverSettings& settings_;
  std::unique_ptr<InterfaceNewton> interface_newton_;
};

// The method, inside augmented-Lagrangian updates if the settings ask for them (updates receives how many).
MethodOutcome run_enforced(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                           MethodRunner& runner, int& updates);

}  // namespace contact::ddm
