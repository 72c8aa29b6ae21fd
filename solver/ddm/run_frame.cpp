#include "run_frame.hpp"

#include <cmath>

namespace contact::ddm {

namespace {

// The marks on one report: the update on every one, the refined counts on the first of an inner solve only.
void mark(IterationReport& r, const InnerMarks& marks, bool first) {
  if (marks.update > 0) r.update = marks.update;
  if (!std::isnan(marks.multiplier)) r.multiplier = marks.multiplier;
  if (first)
    for (size_t a = 0; a < r.bodies.size() && a < marks.refined.size(); ++a)
      r.bodies[a].elements_refined = marks.refined[a];
}

}  // namespace

RunFrame::RunFrame(const SolverSettings& settings, Observer& observer, const CancelToken& cancel,
                   parallel::TaskRunner& runner, Clock::time_point start)
    : settings_(settings), observer_(observer), cancel_(cancel), runner_(runner), start_(start) {}

RunFrame::RunFrame(RunFrame& parent, InnerMarks marks, const Displacements* warm)
    : settings_(parent.settings_),
      observer_(parent.observer_),
      cancel_(parent.cancel_),
      runner_(parent.runner_),
      start_(parent.start_),
      warm_(warm),
      state_(parent.state_),
      parent_(&parent),
      offset_(parent.outcome_.iterations),
      marks_(std::move(marks)) {}

void RunFrame::report(IterationReport r) {
  r.elapsed_seconds = elapsed();
  notify(r);
  outcome_.history.push_back(std::move(r));
}

void RunFrame::report(const AdaptiveStepReport& r) const { observer_.on_adaptive_step(r); }

void RunFrame::report(LoadStepReport r) const {
  r.elapsed_seconds = elapsed();
  observer_.on_load_step(r);
}

void RunFrame::notify(IterationReport r) {
  if (!parent_) {
    observer_.on_iteration(r);
    return;
  }
  r.iteration += offset_;
  mark(r, marks_, !marks_.refined.empty());
  marks_.refined.clear();
  parent_->notify(std::move(r));
}

void RunFrame::append(MethodOutcome inner, const InnerMarks& marks) {
  bool first = true;
  for (auto& r : inner.history) {
    r.iteration += outcome_.iterations;
    mark(r, marks, first);
    first = false;
    outcome_.history.push_back(std::move(r));
  }
  outcome_.iterations += inner.iterations;
  outcome_.updates += inner.updates;
  outcome_.subdomain_solves += inner.subdomain_solves;
  outcome_.interface_iterations += inner.interface_iterations;
  if (!inner.interface_solver.empty()) outcome_.interface_solver = std::move(inner.interface_solver);
  outcome_.gamma = inner.gamma;
  outcome_.u = std::move(inner.u);
  outcome_.z = std::move(inner.z);
  outcome_.q = std::move(inner.q);
  outcome_.rigid_amplitudes = std::move(inner.rigid_amplitudes);
  outcome_.converged = inner.converged;
  outcome_.refused = inner.refused;
  outcome_.stop_reason = inner.stop_reason;
  outcome_.message = std::move(inner.message);
}

}  // namespace contact::ddm
