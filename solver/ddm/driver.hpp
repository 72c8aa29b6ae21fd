// Runs one contact method, with or without augmented-Lagrangian updates, on a ContactSystem: what solve(), the
// load steps and the adaptive loop call.
#pragma once

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

// The method, inside augmented-Lagrangian updates if the settings ask for them (updates receives how many).
MethodOutcome run_enforced(ContactSystem& system, const SolverSettings& settings, RunContext& context,
                           ContactMethod& method, int& updates);

}  // namespace contact::ddm
