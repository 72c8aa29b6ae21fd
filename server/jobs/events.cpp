#include "jobs/events.hpp"

#include "contact/progress_json.hpp"

#include <utility>

namespace contactd {

nlohmann::json state_event(JobState state, const std::string& message, int attempt) {
  return {{"state", to_string(state)}, {"message", message}, {"attempt", attempt}};
}

nlohmann::json iteration_event(const contact::IterationReport& report) { return contact::io::iteration_json(report, true); }

nlohmann::json step_event(const contact::StepSummary& step) { return contact::io::step_json(step); }

nlohmann::json end_event(const JobRecord& r) {
  return {{"state", to_string(r.state)},
          {"stop_reason", r.stop_reason},
          {"message", r.message},
          {"converged", r.converged.value_or(false)},
          {"iterations", r.iterations},
          {"solve_seconds", r.solve_seconds},
          {"result_available", r.result_available}};
}

}  // namespace contactd
