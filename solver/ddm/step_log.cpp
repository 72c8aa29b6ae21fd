#include "step_log.hpp"

#include <utility>

namespace contact::ddm {

void StepLog::push_back(Step step) {
  if (!step.converged && !keep_iterate_) {
    dropped_ = true;
    dropped_step_ = std::move(step);
    return;
  }
  summaries_.push_back(summarize(step));
  if (keep_ == StepOutput::last) {
    steps_.clear();
    nodes_ = 0;
  }
  if (sink_) {  // stored there: only the last stays in memory
    sink_->take(step);
    ++streamed_;
    steps_.clear();
  }
  for (const auto& body : step.bodies) nodes_ += static_cast<double>(body.mesh.num_nodes());
  steps_.push_back(std::move(step));
}

int StepLog::held() const {
  int n = 0;
  for (const auto& s : summaries_) n += s.converged ? 1 : 0;
  return n;
}

}  // namespace contact::ddm
