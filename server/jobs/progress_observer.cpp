#include "jobs/progress_observer.hpp"

#include <memory>
#include <utility>

namespace contactd {

void ProgressObserver::on_iteration(const contact::IterationReport& report) {
  on_iteration_json(contact::io::iteration_json(report, true));
}

void ProgressObserver::on_iteration_json(nlohmann::json full) {
  full.erase("type");  // an MPI run's line names its type; the event log adds it
  nlohmann::json event = contact::io::bounded_progress(full, selection_);
  const int iteration = event.value("iteration", 0);
  if (auto pairs = full.find("pairs"); pairs != full.end() && pairs->is_array())
    job_.set_pair_detail(
        std::make_shared<const nlohmann::json>(nlohmann::json{{"iteration", iteration}, {"pairs", std::move(*pairs)}}));
  job_.events.append("iteration", event);
  nlohmann::json summary = std::move(event);  // the summary is the event without the profiles
  if (summary.contains("pairs") && summary["pairs"].is_array())
    for (auto& pair : summary["pairs"])
      if (pair.is_object()) {
        pair.erase("positions");
        pair.erase("pressures");
        pair.erase("tangential_tractions");
        pair.erase("stick");
      }
  registry_.update_progress(job_, iteration, std::move(summary));
  metrics_.iteration_done();
}

void ProgressObserver::on_adaptive_step(const contact::AdaptiveStepReport& report) {
  on_adaptive_step_json(contact::io::adaptive_step_json(report));
}

void ProgressObserver::on_adaptive_step_json(nlohmann::json step) {
  step.erase("type");
  job_.events.append("adaptive_step", step);
}

void ProgressObserver::on_load_step(const contact::LoadStepReport& report) {
  on_load_step_json(contact::io::load_step_json(report));
}

void ProgressObserver::on_load_step_json(nlohmann::json step) {
  step.erase("type");
  job_.events.append("load_step", step);
}

}  // namespace contactd
