// The one way a nested loop (augmented-Lagrangian updates, load steps, adaptive steps) runs an inner solve and
// folds its outcome into the loop's total, so that iterations run on across the inner solves at every level.
#pragma once

#include "method.hpp"

#include <utility>
#include <vector>

namespace contact::ddm {

// What an inner solve's reports carry besides their iteration number: the augmented-Lagrangian update they
// belong to (if > 0) and, on the first report only, the per-body counts of elements refined before the solve.
struct InnerMarks {
  int update = 0;
  std::vector<int> refined;
};

// Passes reports on with iteration numbers shifted by `offset` and the marks set (OutcomeAccumulator's observer).
class OffsetObserver final : public Observer {
 public:
  OffsetObserver(Observer& inner, int offset, InnerMarks marks) : inner_(inner), offset_(offset), marks_(std::move(marks)) {}
  void on_iteration(const IterationReport& r) override;

 private:
  Observer& inner_;
  int offset_;
  InnerMarks marks_;
};

// A loop's total over its inner solves. run() gives the inner solve a context whose observer numbers the reports
// on from the iterations so far, then append() folds the inner outcome in: its history renumbered and marked the
// same way, its iterations and work (augmented-Lagrangian updates, subdomain solves, interface iterations, the interface solver used) added, and
// the last solve's answer (u, z, q, rigid amplitudes, gamma) and stop (reason, converged, message) written over
// the total's. The loop then says what it adds itself (a prefix to the message, its own stop).
class OutcomeAccumulator {
 public:
  // Runs `solve(RunContext&)` (returning a MethodOutcome) on `context` renumbered from here, starting from `warm`
  // (null: no warm start), and appends its outcome; returns the total.
  template <class Solve>
  MethodOutcome& run(RunContext& context, const Displacements* warm, InnerMarks marks, Solve&& solve) {
    OffsetObserver observer(context.observer, total_.iterations, marks);
    RunContext inner{observer, context.cancel, context.runner, context.start, warm};
    append(solve(inner), marks);
    return total_;
  }

  // Folds one inner solve's outcome in, its reports marked with `marks` (run() does this after the solve).
  void append(MethodOutcome inner, const InnerMarks& marks);

  MethodOutcome& total() { return total_; }
  const MethodOutcome& total() const { return total_; }
  MethodOutcome take() { return std::move(total_); }  // the total, when the loop is done with it

 private:
  MethodOutcome total_;
};

}  // namespace contact::ddm
