#include "step_log.hpp"

#include <utility>

namespace contact::ddm {

void StepLog::push_back(Step step) {
  summaries_.push_back(summarize(step));
  if (keep_ == StepOutput::last) {
    steps_.clear();
    nodes_ = 0;
  }
  for (const auto& body : step.bodies) nodes_ += static_cast<double>(body.mesh.num_nodes());
  steps_.push_back(std::move(step));
}

}  // namespace contact::ddm
