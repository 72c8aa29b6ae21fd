// The steps of a solve (load steps, adaptive steps) as they are reached: every step's scalars (StepSummary, the
// rows of /history/steps) and the fields of every step or of the last one only (Problem::output), so that a run
// that keeps the last step holds one step's fields in memory, not all of them.
#pragma once

#include "contact/problem.hpp"
#include "contact/result.hpp"

#include <vector>

namespace contact::ddm {

class StepLog {
 public:
  explicit StepLog(StepOutput keep = StepOutput::all) : keep_(keep) {}

  // Records the step's scalars and keeps its fields (with StepOutput::last in place of the previous step's).
  void push_back(Step step);
  // The step reached last (push_back must have been called).
  const Step& back() const { return steps_.back(); }
  bool empty() const { return steps_.empty(); }

  // The mesh nodes of the steps whose fields stay kept when another step is pushed (every step's with
  // StepOutput::all, none with last): what a next step adds to the result on top of them.
  double committed_nodes() const { return keep_ == StepOutput::all ? nodes_ : 0.0; }
  bool keeps_all() const { return keep_ == StepOutput::all; }

  std::vector<Step> take_steps() { return std::move(steps_); }
  std::vector<StepSummary> take_summaries() { return std::move(summaries_); }

 private:
  StepOutput keep_;
  std::vector<Step> steps_;
  std::vector<StepSummary> summaries_;
  double nodes_ = 0;  // over steps_
};

}  // namespace contact::ddm
