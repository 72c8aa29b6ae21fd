#include "jobs/progress_observer.hpp"

#include "jobs/events.hpp"

namespace contactd {

void ProgressObserver::on_iteration(const contact::IterationReport& report) {
  on_iteration_json(iteration_event(report));
}

void ProgressObserver::on_iteration_json(const nlohmann::json& event) {
  job_.events.append("iteration", event);
  nlohmann::json summary = event;  // the summary is the event without the pressure profiles
  if (summary.contains("pairs") && summary["pairs"].is_array())
    for (auto& pair : summary["pairs"])
      if (pair.is_object()) {
        pair.erase("positions");
        pair.erase("pressures");
        pair.erase("tangential_tractions");
        pair.erase("stick");
      }
  registry_.update_progress(job_, event.value("iteration", 0), std::move(summary));
  metrics_.iteration_done();
}

}  // namespace contactd
