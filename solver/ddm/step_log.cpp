#include "step_log.hpp"

#include <cmath>
#include <utility>

namespace contact::ddm {

namespace {

// A pair's nodal vector: finite at its contact nodes (status 0); elsewhere NaN marks "no value" (a node not
// opposite the master, a crosspoint: docs/results-format.md), but never an infinity.
bool finite_at_contact_nodes(const Eigen::VectorXd& v, const Eigen::VectorXi& status) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (std::isinf(v[i])) return false;
    const bool contact = i < status.size() && status[i] == 0;
    if (contact && std::isnan(v[i])) return false;
  }
  return true;
}

// Whether every number a reader takes from the step is a number: an iterate a solve stopped on (a diverging
// relaxation, a singular set's system) may hold infinities or NaN, which no result may carry.
bool finite(const Step& step) {
  for (const auto& b : step.bodies)
    if (!b.displacement.allFinite() || !b.stress_node.allFinite() || !b.stress_cell.allFinite() ||
        !b.reaction.allFinite())
      return false;
  for (const auto& p : step.pairs) {
    if (!std::isfinite(p.force) || !std::isfinite(p.tangential_force)) return false;
    for (const Eigen::VectorXd* v : {&p.pressure, &p.normal_gap, &p.tangential_traction, &p.slip})
      if (!finite_at_contact_nodes(*v, p.status)) return false;
  }
  return true;
}

}  // namespace

void StepLog::push_back(Step step) {
  const bool unfit = !step.converged && !finite(step);
  if (!step.converged && (!keep_iterate_ || unfit)) {
    dropped_ = true;
    dropped_unfit_ = unfit;
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
