#include "jobs/events.hpp"

#include "contact/progress_json.hpp"

#include <utility>

namespace contactd {

nlohmann::json state_event(JobState state, const std::string& message, int attempt) {
  return {{"state", to_string(state)}, {"message", message}, {"attempt", attempt}};
}

nlohmann::json iteration_event(const contact::IterationReport& report) { return contact::io::iteration_json(report, true); }

nlohmann::json step_event(const contact::StepSummary& step) { return contact::io::step_json(step); }

nlohmann::json progress_digest(const nlohmann::json& progress) {
  if (!progress.is_object()) return progress;
  auto large = [&](const char* key) {
    const auto it = progress.find(key);
    return it != progress.end() && it->is_array() && it->size() > kDigestItems;
  };
  nlohmann::json out = nlohmann::json::object();
  for (auto it = progress.begin(); it != progress.end(); ++it)
    if (!((it.key() == "pairs" && large("pairs")) || (it.key() == "bodies" && large("bodies")))) out[it.key()] = it.value();
  auto number = [](const nlohmann::json& item, const char* key) {
    const auto it = item.find(key);
    return it != item.end() && it->is_number() ? it->get<double>() : 0.0;
  };
  if (const auto pairs = progress.find("pairs"); pairs != progress.end() && pairs->is_array() && pairs->size() > kDigestItems) {
    double force = 0, active = 0, changed = 0, max_pressure = 0;
    int pairs_changed = 0;
    std::string max_pair;
    for (const auto& pair : *pairs) {
      if (!pair.is_object()) continue;
      force += number(pair, "force");
      active += number(pair, "active_nodes");
      const double c = number(pair, "changed_nodes");
      changed += c;
      pairs_changed += c > 0;
      if (number(pair, "max_pressure") > max_pressure || max_pair.empty()) {
        max_pressure = number(pair, "max_pressure");
        max_pair = pair.value("name", std::string());
      }
    }
    out["pairs_summary"] = {{"count", pairs->size()},          {"force", force},
                            {"active_nodes", active},          {"changed_nodes", changed},
                            {"pairs_changed", pairs_changed},  {"max_pressure", max_pressure},
                            {"max_pressure_pair", max_pair}};
  }
  if (const auto bodies = progress.find("bodies"); bodies != progress.end() && bodies->is_array() && bodies->size() > kDigestItems) {
    double elements = 0, dofs = 0, refined = 0;
    for (const auto& body : *bodies) {
      if (!body.is_object()) continue;
      elements += number(body, "elements");
      dofs += number(body, "dofs");
      refined += number(body, "elements_refined");
    }
    out["bodies_summary"] = {{"count", bodies->size()}, {"elements", elements}, {"dofs", dofs}, {"elements_refined", refined}};
  }
  return out;
}

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
