#include "contact/progress_json.hpp"

namespace contact::io {

nlohmann::json iteration_json(const IterationReport& report, bool with_profiles) {
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& b : report.bodies)
    bodies.push_back(
        {{"name", b.name}, {"elements", b.elements}, {"dofs", b.dofs}, {"elements_refined", b.elements_refined}});
  nlohmann::json pairs = nlohmann::json::array();
  for (const auto& p : report.pairs) {
    nlohmann::json pair = {{"name", p.name},
                           {"force", p.force},
                           {"resultant", {p.resultant.x(), p.resultant.y()}},
                           {"max_pressure", p.max_pressure},
                           {"extent_begin", p.extent_begin},
                           {"extent_end", p.extent_end},
                           {"active_nodes", p.active_nodes},
                           {"changed_nodes", p.changed_nodes},
                           {"theta", p.theta},
                           {"max_penetration", p.max_penetration}};
    if (!p.stick.empty()) {  // friction pairs only
      pair["friction"] = p.friction;
      pair["friction_coefficient"] = p.friction_coefficient;
      pair["friction_bound"] = p.friction_bound;
      pair["tangential_force"] = p.tangential_force;
    }
    if (with_profiles) {
      pair["positions"] = p.positions;
      pair["pressures"] = p.pressures;
      if (!p.stick.empty()) {
        pair["tangential_tractions"] = p.tangential_tractions;
        pair["stick"] = p.stick;
      }
    }
    pairs.push_back(std::move(pair));
  }
  nlohmann::json j = {{"iteration", report.iteration},
                      {"measure", to_string(report.measure)},
                      {"paper_criterion", report.paper_criterion},
                      {"fixed_point_residual", report.fixed_point_residual},
                      {"complementarity", report.complementarity},
                      {"active_nodes", report.active_nodes},
                      {"active_set_changes", report.active_set_changes},
                      {"elapsed_seconds", report.elapsed_seconds},
                      {"gamma", report.gamma},
                      {"update", report.update},
                      {"note", report.note},
                      {"bodies", bodies},
                      {"pairs", pairs}};
  return j;
}

nlohmann::json step_json(const StepSummary& step) {
  nlohmann::json bodies = nlohmann::json::array();
  for (size_t b = 0; b < step.body_names.size(); ++b)
    bodies.push_back({{"name", step.body_names[b]}, {"elements", step.elements[b]}, {"nodes", step.nodes[b]}});
  return {{"step", step.index}, {"iteration", step.iteration}, {"bodies", bodies}};
}

}  // namespace contact::io
