#include "jobs/events.hpp"

#include "contact/progress_json.hpp"

#include <utility>

namespace contactd {

nlohmann::json state_event(JobState state, const std::string& message, int attempt) {
  return {{"state", to_string(state)}, {"message", message}, {"attempt", attempt}};
}

nlohmann::json step_event(const contact::StepSummary& step) { return contact::io::step_json(step); }

nlohmann::json progress_digest(const nlohmann::json& progress) {
  if (!progress.is_object()) return progress;
  nlohmann::json out = nlohmann::json::object();
  for (auto it = progress.begin(); it != progress.end(); ++it) {
    const bool list = (it.key() == "pairs" || it.key() == "bodies") && it->is_array();
    if (!list || it->size() <= kDigestItems) out[it.key()] = it.value();
  }
  // The totals are in every event since they are bounded; a progress stored by an older server has none.
  if (!out.contains("pairs_summary") && progress.contains("pairs") && progress["pairs"].is_array())
    out["pairs_summary"] = contact::io::pairs_summary(progress["pairs"]);
  if (!out.contains("bodies_summary") && progress.contains("bodies") && progress["bodies"].is_array())
    out["bodies_summary"] = contact::io::bodies_summary(progress["bodies"]);
  return out;
}

nlohmann::json end_event(const JobRecord& r) {
  return {{"state", to_string(r.state)},
          {"stop_reason", r.stop_reason},
          {"message", r.message},
          {"converged", r.converged.value_or(false)},
          {"iterations", r.iterations},
          {"solve_seconds", r.solve_seconds},
          {"result_available", r.result_available},
          {"warnings", r.warnings},
          {"collapse", r.collapse}};
}

}  // namespace contactd
