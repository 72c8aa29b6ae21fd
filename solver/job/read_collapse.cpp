// A collapse analysis ("collapse": {...}) and its live loads ("live": true on a load or on a body force): what they
// are and what they require of the rest of the job (docs/job-format.md, "Collapse analysis").
#include "job_reader.hpp"

namespace contact::job::detail {

bool JobReader::read_live(const Fields& condition) {
  const json* v = condition.find("live");
  if (!v) return false;
  const std::string pointer = condition.at("live");
  const auto live = read::boolean(*v, pointer, "live", errors_);
  if (!live || !*live) return false;
  if (condition.has("displacement") || condition.has("free")) {
    errors_.add(pointer,
                "live marks a load (a traction, a force or a body force) that the collapse analysis raises; a "
                "prescribed displacement or \"free\" is not a load: remove live, or give the load on its own");
    return false;
  }
  if (condition.has("history")) {
    errors_.add(pointer,
                "a live load follows the collapse multiplier, not a history of its own: give it without history "
                "(the loading's steps, with the histories, bring the dead loads on before the multiplier rises)");
    return false;
  }
  return true;
}

// "collapse": {"tolerance": 1e-3, "first": lambda_1, "max_multiplier": 1e6, "max_solves": 60}, every field optional.
void JobReader::read_collapse(const Fields& top) {
  const json* v = top.find("collapse");
  if (!v) return;
  collapse_pointer_ = top.at("collapse");
  Fields f(*v, collapse_pointer_, "collapse", {"tolerance", "first", "max_multiplier", "max_solves"}, errors_);
  if (!f.ok()) return;
  CollapseSpec& c = problem_.collapse;
  c.enabled = true;
  json& out = sub_object(normalized_, "collapse");
  if (const json* t = f.find("tolerance"))
    if (auto x = positive(*t, f.at("tolerance"), "tolerance", errors_)) {
      if (*x < 1e-8 || *x > 0.5)
        errors_.add(f.at("tolerance"), "tolerance = " + format_number(*x) +
                                           " is outside [1e-8, 0.5]: the bracket's width relative to the "
                                           "multiplier that held");
      else
        c.tolerance = *x;
    }
  set_default(out, "tolerance", CollapseSpec{}.tolerance);
  if (const json* t = f.find("first"))
    if (auto x = positive(*t, f.at("first"), "first", errors_)) c.first = *x;
  if (const json* t = f.find("max_multiplier"))
    if (auto x = positive(*t, f.at("max_multiplier"), "max_multiplier", errors_)) c.max_multiplier = *x;
  set_default(out, "max_multiplier", CollapseSpec{}.max_multiplier);
  if (c.first > c.max_multiplier)
    errors_.add(f.at("first"),
                "first = " + format_number(c.first) + " is above max_multiplier = " + format_number(c.max_multiplier));
  if (const json* t = f.find("max_solves"))
    if (auto x = bounded_int(*t, f.at("max_solves"), "max_solves", 2, errors_, 1000)) c.max_solves = *x;
  set_default(out, "max_solves", CollapseSpec{}.max_solves);
}

void JobReader::check_collapse() {
  size_t live = 0;
  for (const auto& in : inputs_) live += in.live_pointers.size();
  if (!problem_.collapse.enabled) {
    for (const auto& in : inputs_)
      for (const auto& at : in.live_pointers)
        errors_.add(at,
                    "a live load is raised by a collapse analysis, and the job asks for none: add \"collapse\": {} "
                    "(docs/job-format.md, \"Collapse analysis\"), or remove live to apply the load as it is");
    return;
  }
  if (live == 0 && !inputs_.empty())
    errors_.add(collapse_pointer_,
                "a collapse analysis raises the live loads, and no load is live: mark the loads to raise with "
                "\"live\": true (a boundary condition's traction or force, or a body_force given as {\"value\": "
                "[x, y], \"live\": true}); the others are held as dead loads");
  if (problem_.adaptivity.enabled)
    errors_.add(collapse_pointer_,
                "a collapse analysis on adaptive meshes is not supported: solve it on fixed meshes (remove "
                "adaptivity, or refine the meshes where the joints are)");
}

}  // namespace contact::job::detail
