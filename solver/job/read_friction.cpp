// Friction of a contact pair ("friction": {"coefficient": mu} or {"bound": g}), a boundary condition's own load
// history ("history": [f_1, ..., f_n]), and what they require of the rest of the job: the number of load steps,
// a method and enforcement that solve friction (docs/job-format.md, "Friction").
#include "job_reader.hpp"

namespace contact::job::detail {

void JobReader::read_friction(const Fields& contact, FrictionSpec& friction) {
  const json* v = contact.find("friction");
  if (!v) return;
  const size_t before = errors_.size();
  Fields f(*v, contact.at("friction"), "friction", {"coefficient", "bound"}, errors_);
  if (!f.ok() || errors_.size() > before) return;  // (an unknown field is the error to read first)
  if (f.has("coefficient") == f.has("bound")) {
    errors_.add(contact.at("friction"),
                "give exactly one of coefficient (Coulomb's mu: |t| <= mu p) and bound "
                "(Tresca's g: |t| <= g, a traction like the pressure)");
    return;
  }
  const std::string key = f.has("coefficient") ? "coefficient" : "bound";
  const auto x = read::number(*f.find(key), f.at(key), key, errors_);
  if (!x) return;
  if (*x < 0) {
    errors_.add(f.at(key), key + " = " + format_number(*x) + " is negative: " +
                               (key == "coefficient" ? "a friction coefficient is >= 0 (0: frictionless)"
                                                     : "a friction bound is a traction magnitude, >= 0"));
    return;
  }
  friction.law = key == "coefficient" ? FrictionSpec::Law::coulomb : FrictionSpec::Law::tresca;
  (key == "coefficient" ? friction.coefficient : friction.bound) = *x;
}

void JobReader::read_history(const Fields& condition, std::vector<double>& history) {
  const json* v = condition.find("history");
  if (!v) return;
  const std::string pointer = condition.at("history");
  if (!v->is_array() || v->empty()) {
    errors_.add(pointer,
                "history must be a non-empty array of load factors, one per load step, got " + read::type_name(*v));
    return;
  }
  if (static_cast<long>(v->size()) > limits_.max_load_steps) {
    errors_.add(pointer, "history has " + std::to_string(v->size()) + " entries: at most " +
                             std::to_string(limits_.max_load_steps) + " load steps");
    return;
  }
  for (size_t k = 0; k < v->size(); ++k)
    if (auto x = read::number((*v)[k], child(pointer, k), "load factor", errors_)) history.push_back(*x);
}

// After the bodies, contacts, solver and loading are read: a history has one factor per load step; friction
// needs the exact interface problem (interface_newton with its direct solver, or the monolithic reference).
void JobReader::check_friction_and_histories() {
  const size_t steps = problem_.loading.factors.size();
  // A history at `at` (a condition, or a body force given with one).
  auto check_history = [&](const std::vector<double>& h, const std::string& at) {
    if (!h.empty() && problem_.adaptivity.enabled && problem_.adaptivity.strategy == AdaptStrategy::paper)
      errors_.add(child(at, "history"),
                  "a load history needs load steps, which the adaptive strategy \"paper\" does not take (use "
                  "\"converge_then_refine\")");
    else if (!h.empty() && h.size() != steps && loading_read_)  // else the number of steps is not known
      errors_.add(child(at, "history"), "history has " + std::to_string(h.size()) + " load factors but the job has " +
                                            std::to_string(steps) + " load step" + (steps == 1 ? "" : "s") +
                                            " (loading): give one factor per step");
  };
  for (const auto& in : inputs_) {
    for (size_t j = 0; j < in.body.boundary.size() && j < in.condition_pointers.size(); ++j)
      check_history(in.body.boundary[j].history, in.condition_pointers[j]);
    if (!in.body_force_pointer.empty()) check_history(in.body.body_force_history, in.body_force_pointer);
  }
  const SolverSettings& s = problem_.solver;
  for (size_t k = 0; k < problem_.contacts.size() && k < friction_pointers_.size(); ++k) {
    if (!problem_.contacts[k].friction.active()) continue;
    const std::string& at = friction_pointers_[k];
    if (const std::string conflict = friction_conflict(s); !conflict.empty()) {
      const std::string& where = iterates_on_penalty(s.method) ? method_.pointer : enforcement_.pointer;
      errors_.add(at, conflict + (where.empty() ? "" : " at " + where));
      return;
    }
    if (problem_.adaptivity.enabled && problem_.adaptivity.strategy == AdaptStrategy::paper) {
      errors_.add(at,
                  "friction with the adaptive strategy \"paper\" is not supported (its penalty iteration is "
                  "frictionless): use strategy \"converge_then_refine\"");
      return;
    }
  }
}

}  // namespace contact::job::detail
