#include "contact/progress_json.hpp"

#include <fnmatch.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace contact::io {

namespace {

nlohmann::json pair_json(const PairReport& p, bool profiles) {
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
    // Over the slave nodes in contact (pressure > 0; an open node's stick flag says nothing). Counted at the
    // nodes, like the profiles: a multiplier segment's inner nodes count too, so stick + slip can exceed
    // active_nodes, which counts the multipliers.
    int stick = 0, slip = 0;
    for (size_t k = 0; k < p.stick.size() && k < p.pressures.size(); ++k)
      if (p.pressures[k] > 0) (p.stick[k] != 0 ? stick : slip) += 1;
    pair["friction"] = p.friction;
    pair["friction_coefficient"] = p.friction_coefficient;
    pair["friction_bound"] = p.friction_bound;
    pair["tangential_force"] = p.tangential_force;
    pair["stick_nodes"] = stick;
    pair["slip_nodes"] = slip;
  }
  if (profiles) {
    pair["positions"] = p.positions;
    pair["pressures"] = p.pressures;
    if (!p.stick.empty()) {
      pair["tangential_tractions"] = p.tangential_tractions;
      pair["stick"] = p.stick;
    }
  }
  return pair;
}

double number(const nlohmann::json& item, const char* key) {
  const auto it = item.find(key);
  return it != item.end() && it->is_number() ? it->get<double>() : 0.0;
}

}  // namespace

nlohmann::json adaptive_step_json(const AdaptiveStepReport& r) {
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& b : r.bodies)
    bodies.push_back({{"name", b.name}, {"cells", b.elements}, {"unknowns", b.dofs}, {"refined", b.elements_refined}});
  return {{"step", r.step},
          {"bodies", std::move(bodies)},
          {"estimate", r.estimate},
          {"pressure_estimate", r.pressure_estimate},
          {"force", r.force},
          {"peak_pressure", r.peak_pressure},
          {"compared_with", r.compared_with},
          {"estimate_change", r.estimate_change},
          {"force_change", r.force_change},
          {"peak_change", r.peak_change},
          {"extent_change", r.extent_change},
          {"stick_change", r.stick_change},
          {"tangential_change", r.tangential_change},
          {"indicator_seconds", r.indicator_seconds},
          {"elapsed_seconds", r.elapsed_seconds}};
}

nlohmann::json iteration_json(const IterationReport& report, bool profiles) {
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& b : report.bodies)
    bodies.push_back(
        {{"name", b.name}, {"elements", b.elements}, {"dofs", b.dofs}, {"elements_refined", b.elements_refined}});
  nlohmann::json pairs = nlohmann::json::array();
  for (const auto& p : report.pairs) pairs.push_back(pair_json(p, profiles));
  nlohmann::json out = {{"iteration", report.iteration},
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
                        {"bodies", std::move(bodies)},
                        {"pairs", std::move(pairs)}};
  // A collapse analysis's trials: the multiplier being tried (docs/progress.md).
  if (!std::isnan(report.multiplier)) out["multiplier"] = report.multiplier;
  return out;
}

bool matches_any(const std::string& name, const std::vector<std::string>& patterns) {
  for (const auto& pattern : patterns)
    if (::fnmatch(pattern.c_str(), name.c_str(), 0) == 0) return true;
  return false;
}

nlohmann::json pairs_summary(const nlohmann::json& pairs) {
  double force = 0, tangential = 0, active = 0, changed = 0, stick = 0, slip = 0;
  double max_pressure = 0, most_changed = 0, max_penetration = 0;
  int pairs_changed = 0, friction_pairs = 0;
  std::string max_pressure_pair, most_changed_pair;
  std::size_t count = 0;
  for (const auto& pair : pairs) {
    if (!pair.is_object()) continue;
    ++count;
    force += number(pair, "force");
    active += number(pair, "active_nodes");
    const double c = std::abs(number(pair, "changed_nodes"));
    changed += c;
    pairs_changed += c > 0;
    if (c > most_changed) {
      most_changed = c;
      most_changed_pair = pair.value("name", std::string());
    }
    if (pair.contains("tangential_force")) {
      ++friction_pairs;
      tangential += number(pair, "tangential_force");
      stick += number(pair, "stick_nodes");
      slip += number(pair, "slip_nodes");
    }
    if (const double p = number(pair, "max_pressure"); p > max_pressure) {
      max_pressure = p;
      max_pressure_pair = pair.value("name", std::string());
    }
    max_penetration = std::max(max_penetration, number(pair, "max_penetration"));
  }
  return {{"count", count},
          {"force", force},
          {"tangential_force", tangential},
          {"active_nodes", active},
          {"changed_nodes", changed},
          {"pairs_changed", pairs_changed},
          {"friction_pairs", friction_pairs},
          {"stick_nodes", stick},
          {"slip_nodes", slip},
          {"max_pressure", max_pressure},
          {"max_pressure_pair", max_pressure_pair},
          {"most_changed_pair", most_changed_pair},
          {"most_changed_nodes", most_changed},
          {"max_penetration", max_penetration}};
}

nlohmann::json bodies_summary(const nlohmann::json& bodies) {
  double elements = 0, dofs = 0, refined = 0;
  std::size_t count = 0;
  for (const auto& body : bodies) {
    if (!body.is_object()) continue;
    ++count;
    elements += number(body, "elements");
    dofs += number(body, "dofs");
    refined += number(body, "elements_refined");
  }
  return {{"count", count}, {"elements", elements}, {"dofs", dofs}, {"elements_refined", refined}};
}

nlohmann::json bounded_progress(nlohmann::json full, const ProgressSelection& selection) {
  if (!full.is_object()) return full;
  auto pairs = full.find("pairs");
  if (pairs != full.end() && pairs->is_array()) {
    nlohmann::json summary = pairs_summary(*pairs);
    const bool every = selection.all || (selection.patterns.empty() && pairs->size() <= kPairsListedAll);
    if (!every) {
      const std::string peak = summary["max_pressure_pair"], changing = summary["most_changed_pair"];
      nlohmann::json listed = nlohmann::json::array();
      std::size_t selected = 0;
      for (auto& pair : *pairs) {
        const std::string name = pair.is_object() ? pair.value("name", std::string()) : std::string();
        const bool chosen = selected < kMaxPairsSelected && matches_any(name, selection.patterns);
        selected += chosen;
        if (chosen || (!name.empty() && (name == peak || name == changing))) listed.push_back(std::move(pair));
      }
      *pairs = std::move(listed);
    }
    full["pairs_summary"] = std::move(summary);
    full["pairs_listed"] = every ? "all" : "selected";
  }
  auto bodies = full.find("bodies");
  if (bodies != full.end() && bodies->is_array()) {
    full["bodies_summary"] = bodies_summary(*bodies);
    const bool every = bodies->size() <= kBodiesListedAll;
    if (!every) full.erase("bodies");
    full["bodies_listed"] = every ? "all" : "none";
  }
  return full;
}

nlohmann::json step_json(const StepSummary& step) {
  nlohmann::json bodies = nlohmann::json::array();
  long elements = 0, nodes = 0;
  for (size_t b = 0; b < step.body_names.size(); ++b) {
    elements += step.elements[b];
    nodes += step.nodes[b];
    if (step.body_names.size() <= kBodiesListedAll)
      bodies.push_back({{"name", step.body_names[b]}, {"elements", step.elements[b]}, {"nodes", step.nodes[b]}});
  }
  nlohmann::json j = {
      {"step", step.index},
      {"iteration", step.iteration},
      {"bodies_summary", {{"count", step.body_names.size()}, {"elements", elements}, {"nodes", nodes}}}};
  if (step.body_names.size() <= kBodiesListedAll) j["bodies"] = std::move(bodies);
  if (step.multiplier != 0.0) j["multiplier"] = step.multiplier;
  return j;
}

nlohmann::json load_step_json(const LoadStepReport& r) {
  const char* kinds[] = {"held", "cut", "trial"};
  nlohmann::json j = {{"kind", kinds[static_cast<int>(r.kind)]},
                      {"step", r.step},
                      {"load_factor", r.load_factor},
                      {"iterations", r.iterations},
                      {"elapsed_seconds", r.elapsed_seconds}};
  if (r.kind == LoadStepReport::Kind::trial) {
    j["multiplier"] = r.multiplier;
    j["held"] = r.held;
  } else {
    j["steps"] = r.steps;
    j["fraction"] = r.fraction;
    if (r.kind == LoadStepReport::Kind::cut) j["next"] = r.next;
  }
  return j;
}

std::string load_step_words(const nlohmann::json& e) {
  char text[256];
  const std::string kind = e.value("kind", "");
  const int iterations = e.value("iterations", 0);
  if (kind == "trial") {
    std::snprintf(text, sizeof text, "collapse trial %d: multiplier %.6g %s (%d iterations)", e.value("step", 0),
                  e.value("multiplier", 0.0), e.value("held", false) ? "held" : "did not hold", iterations);
  } else if (kind == "cut") {
    std::snprintf(text, sizeof text,
                  "load step %d of %d cut: held up to %.4g %% of the step (load factor %.6g), now trying %.4g %%",
                  e.value("step", 0), e.value("steps", 0), 100 * e.value("fraction", 0.0), e.value("load_factor", 0.0),
                  100 * e.value("next", 0.0));
  } else {
    const double fraction = e.value("fraction", 1.0);
    if (fraction < 1.0)
      std::snprintf(text, sizeof text, "load step %d of %d: sub-step to %.4g %% held (load factor %.6g, %d iterations)",
                    e.value("step", 0), e.value("steps", 0), 100 * fraction, e.value("load_factor", 0.0), iterations);
    else
      std::snprintf(text, sizeof text, "load step %d of %d held at load factor %.6g (%d iterations)",
                    e.value("step", 0), e.value("steps", 0), e.value("load_factor", 0.0), iterations);
  }
  return text;
}

namespace {

// A mechanism (limit/mechanism.hpp) as the job resource and the end event show it.
nlohmann::json mechanism_json(const Mechanism& m) {
  nlohmann::json bodies = nlohmann::json::array(), joints = nlohmann::json::array();
  for (const auto& b : m.bodies)
    bodies.push_back(
        {{"body", b.body},
         {"velocity", {b.velocity.x(), b.velocity.y()}},
         {"omega", b.omega},
         {"centre", std::isnan(b.centre.x()) ? nlohmann::json(nullptr) : nlohmann::json{b.centre.x(), b.centre.y()}},
         {"words", b.words}});
  for (const auto& j : m.joints)
    joints.push_back({{"pair", j.pair},
                      {"kind", j.kind},
                      {"point", {j.point.x(), j.point.y()}},
                      {"slip", j.slip},
                      {"opening", j.opening},
                      {"words", j.words}});
  return {{"kind", m.kind},   {"words", m.words}, {"source", m.source},
          {"check", m.check}, {"bodies", bodies}, {"joints", joints}};
}

}  // namespace

nlohmann::json collapse_json(const CollapseResult& c) {
  if (!c.analysed) return nullptr;
  // JSON has no NaN or infinity: a bound or a failure not known is null, an unbounded statics "inf".
  auto number = [](double x) -> nlohmann::json {
    if (std::isnan(x)) return nullptr;
    if (std::isinf(x)) return "inf";
    return x;
  };
  nlohmann::json trials = nlohmann::json::array();
  for (const auto& t : c.trials)
    trials.push_back({{"multiplier", t.multiplier},
                      {"held", t.held},
                      {"iterations", t.iterations},
                      {"seconds", t.seconds},
                      {"displacement", number(t.displacement)}});
  nlohmann::json thrust = nlohmann::json::array();
  for (const auto& t : c.thrust)
    thrust.push_back(
        {{"pair", t.pair},
         {"slave_body", t.slave_body},
         {"master_body", t.master_body},
         {"point", t.point.allFinite() ? nlohmann::json{t.point.x(), t.point.y()} : nlohmann::json(nullptr)},
         {"edge", {{t.first.x(), t.first.y()}, {t.last.x(), t.last.y()}}},
         {"force", t.force},
         {"eccentricity", number(t.eccentricity)}});
  return {{"verdict", c.verdict},
          {"held", c.held},
          {"failed", number(c.failed)},
          {"failed_by_statics", c.failed_by_statics},
          {"failed_by_budget", c.failed_by_budget},
          {"tolerance", c.tolerance},
          {"solves", c.solves},
          {"bracket_solves", c.bracket_solves},
          {"statics_bound", number(c.statics_bound)},
          {"words", c.words},
          {"trials", trials},
          {"start_displacement", number(c.start_displacement)},
          {"thrust", thrust},
          {"mechanism", mechanism_json(c.mechanism)},
          {"statics_mechanism", mechanism_json(c.statics_mechanism)}};
}

}  // namespace contact::io
