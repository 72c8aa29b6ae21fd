#include "outcome_accumulator.hpp"

namespace contact::ddm {

namespace {

// The marks on one report: the update on every one, the refined counts on the first of an inner solve only.
void mark(IterationReport& r, const InnerMarks& marks, bool first) {
  if (marks.update > 0) r.update = marks.update;
  if (first)
    for (size_t a = 0; a < r.bodies.size() && a < marks.refined.size(); ++a) r.bodies[a].elements_refined = marks.refined[a];
}

}  // namespace

void OffsetObserver::on_iteration(const IterationReport& r) {
  IterationReport copy = r;
  copy.iteration += offset_;
  mark(copy, marks_, !marks_.refined.empty());
  marks_.refined.clear();
  inner_.on_iteration(copy);
}

void OutcomeAccumulator::append(MethodOutcome inner, const InnerMarks& marks) {
  bool first = true;
  for (auto& r : inner.history) {
    r.iteration += total_.iterations;
    mark(r, marks, first);
    first = false;
    total_.history.push_back(std::move(r));
  }
  total_.iterations += inner.iterations;
  total_.updates += inner.updates;
  total_.solves_per_body += inner.solves_per_body;
  total_.interface_iterations += inner.interface_iterations;
  if (!inner.interface_solver.empty()) total_.interface_solver = std::move(inner.interface_solver);
  total_.gamma = inner.gamma;
  total_.u = std::move(inner.u);
  total_.z = std::move(inner.z);
  total_.q = std::move(inner.q);
  total_.rigid_amplitudes = std::move(inner.rigid_amplitudes);
  total_.converged = inner.converged;
  total_.refused = inner.refused;
  total_.reason = inner.reason;
  total_.message = std::move(inner.message);
}

}  // namespace contact::ddm
