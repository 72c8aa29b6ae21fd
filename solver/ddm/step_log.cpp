#include "step_log.hpp"

#include <utility>

namespace contact::ddm {

void StepLog::push_back(Step step) {
  summaries_.push_back(summarize(step));
  if (keep_ == StepOutput::last) steps_.clear();
  steps_.push_back(std::move(step));
}

}  // namespace contact::ddm
