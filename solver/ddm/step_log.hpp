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
  explicit StepLog(StepOutput keep = StepOutput::all, bool keep_iterate = true, StepSink* sink = nullptr)
      : keep_(keep), keep_iterate_(keep_iterate), sink_(keep == StepOutput::all ? sink : nullptr) {}
  // With a sink, the steps go to it as they are recorded and only the last stays here (StepOutput::all only: with
  // last, a step is replaced by the next one and never stored before the end).
  explicit StepLog(const OutputSettings& output, StepSink* sink = nullptr)
      : StepLog(output.steps, output.iterate, sink) {}

  // Records the step's scalars and keeps its fields (with StepOutput::last in place of the previous step's). A step
  // that did not converge is an iterate, no answer: without keep_iterate (OutputSettings::iterate), or with
  // non-finite values, it is not recorded at all, so that with StepOutput::last the step that held before it
  // stays the one kept.
  void push_back(Step step);
  // The step kept last (push_back must have recorded one).
  const Step& back() const { return steps_.back(); }
  // The iterate push_back left out, if it left one out: not in the result, but checks of what the run stopped on
  // (a floating body its contacts do not hold) still look at it.
  bool dropped_iterate() const { return dropped_; }
  // Whether it was left out, asked for or not, because it holds non-finite values.
  bool dropped_unfit() const { return dropped_unfit_; }
  const Step& dropped_step() const { return dropped_step_; }
  bool empty() const { return steps_.empty(); }
  // How many of the steps recorded converged (every step's, whatever StepOutput keeps of their fields).
  int held() const;
  // Whether the last step recorded is an iterate that did not converge (kept with keep_iterate).
  bool ends_with_iterate() const { return !summaries_.empty() && !summaries_.back().converged; }

  // The mesh nodes of the steps whose fields stay kept when another step is pushed (every step's with
  // StepOutput::all, streamed or not, none with last): what a next step adds to the result on top of them.
  double committed_nodes() const { return keep_ == StepOutput::all ? nodes_ : 0.0; }
  bool keeps_all() const { return keep_ == StepOutput::all; }

  std::vector<Step> take_steps() { return std::move(steps_); }
  int streamed() const { return streamed_; }  // the steps the sink took
  std::vector<StepSummary> take_summaries() { return std::move(summaries_); }

 private:
  StepOutput keep_;
  bool keep_iterate_;
  StepSink* sink_;
  int streamed_ = 0;
  bool dropped_ = false, dropped_unfit_ = false;
  Step dropped_step_;
  std::vector<Step> steps_;
  std::vector<StepSummary> summaries_;
  double nodes_ = 0;  // over steps_
};

}  // namespace contact::ddm
