// The job's settings: "solver" (with the method and enforcement defaults, which depend on the adaptive strategy),
// "adaptivity", "loading", "parallel" and "output" (its default depends on adaptivity).
#include "job_reader.hpp"

#include "contact/progress_json.hpp"
#include "names.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace contact::job::detail {

void JobReader::read_solver(const Fields& top) {
  json& out = sub_object(normalized_, "solver");
  if (const json* v = top.find("solver")) read_solver_fields(*v, top.at("solver"), out);
  write_solver_defaults(out);
}

// The fields of "solver" the job gives (the defaults of the others: write_solver_defaults).
void JobReader::read_solver_fields(const json& value, const std::string& pointer, json& out) {
  SolverSettings& s = problem_.solver;
  Fields f(value, pointer, "solver",
           {"method", "penalty", "gamma", "tolerance", "criterion", "max_iterations", "initial_guess", "threads",
            "acceleration", "anderson_depth", "robin", "enforcement", "augmented_lagrangian", "interface"},
           errors_);
  if (const json* m = f.find("method")) read_method(*m, f.at("method"));
  if (const json* p = f.find("penalty")) read_penalty(*p, f.at("penalty"), sub_object(out, "penalty"));
  if (const json* g = f.find("gamma")) read_gamma(*g, f.at("gamma"));
  if (const json* t = f.find("tolerance"))
    if (auto x = positive(*t, f.at("tolerance"), "tolerance", errors_)) s.tolerance = *x;
  if (const json* c = f.find("criterion")) read_name(*c, f.at("criterion"), "criterion", s.criterion, errors_);
  if (const json* n = f.find("max_iterations"))
    if (auto x = bounded_int(*n, f.at("max_iterations"), "max_iterations", 1, errors_)) s.max_iterations = *x;
  if (const json* g = f.find("initial_guess"))
    read_name(*g, f.at("initial_guess"), "initial_guess", s.initial_guess, errors_);
  if (const json* t = f.find("threads"))
    if (auto x = bounded_int(*t, f.at("threads"), "threads", 0, errors_)) s.threads = *x;
  if (const json* a = f.find("acceleration"))
    read_name(*a, f.at("acceleration"), "acceleration", s.acceleration, errors_);
  if (const json* d = f.find("anderson_depth")) {
    if (auto x = bounded_int(*d, f.at("anderson_depth"), "anderson_depth", 1, errors_)) {
      if (*x > 50)
        errors_.add(f.at("anderson_depth"), "anderson_depth = " + std::to_string(*x) + " is above 50");
      else
        s.anderson_depth = *x;
    }
  }
  if (const json* r = f.find("robin")) read_robin(*r, f.at("robin"));
  if (const json* e = f.find("enforcement")) read_enforcement(*e, f.at("enforcement"));
  if (const json* a = f.find("augmented_lagrangian")) read_augmented_lagrangian(*a, f.at("augmented_lagrangian"));
  if (const json* i = f.find("interface")) read_interface_solver(*i, f.at("interface"));
}

// "method": remembered as given (resolve_method_defaults fills it in otherwise).
void JobReader::read_method(const json& value, const std::string& pointer) {
  method_.pointer = pointer;
  if (auto x = choice(value, pointer, "method", method_names(), errors_)) {
    problem_.solver.method = *method_named(*x);
    method_.valid = true;
  }
}

// "gamma": a relaxation weight in (0, 2) or "auto".
void JobReader::read_gamma(const json& value, const std::string& pointer) {
  SolverSettings& s = problem_.solver;
  if (value.is_string()) {
    if (value.get<std::string>() == "auto")
      s.gamma_auto = true;
    else
      errors_.add(pointer, "gamma must be a number in (0, 2) or \"auto\", got \"" +
                               read::shown(value.get<std::string>()) + "\"");
  } else {
    auto x = read::number(value, pointer, "gamma", errors_);
    if (x && !(*x > 0 && *x < 2))
      errors_.add(pointer, "gamma = " + format_number(*x) +
                               " is outside (0, 2): the relaxation weight must be greater than 0 and less than 2");
    else if (x) {
      s.gamma = *x;
      s.gamma_auto = false;
    }
  }
}

// "enforcement": remembered as given (resolve_method_defaults fills it in otherwise).
void JobReader::read_enforcement(const json& value, const std::string& pointer) {
  enforcement_.pointer = pointer;
  if (auto x = choice(value, pointer, "enforcement", enforcement_names(), errors_)) {
    problem_.solver.enforcement = *enforcement_named(*x);
    enforcement_.valid = true;
  }
}

// Every default of "solver" into the normalized copy: SolverSettings' own (contact/problem.hpp), so that the
// copy says what a Problem left at its defaults runs. Method and enforcement depend on the rest of the job
// (resolve_method_defaults).
void JobReader::write_solver_defaults(json& out) {
  const SolverSettings d;
  set_default(out, "penalty", json{{"c", d.penalty.c}});
  set_default(out, "gamma", d.gamma_auto ? json("auto") : json(d.gamma));
  set_default(out, "tolerance", d.tolerance);
  set_default(out, "criterion", name_of(d.criterion));
  set_default(out, "max_iterations", d.max_iterations);
  set_default(out, "initial_guess", name_of(d.initial_guess));
  set_default(out, "threads", d.threads);
  set_default(out, "acceleration", name_of(d.acceleration));
  set_default(out, "anderson_depth", d.anderson_depth);
  // Written only where "robin" is left out: a given "robin" without psi stays as given (psi "active_set").
  set_default(out, "robin", json{{"psi", d.robin.active_set ? json("active_set") : json(d.robin.psi)}});
  json& al = sub_object(out, "augmented_lagrangian");
  set_default(al, "tolerance", d.augmented_lagrangian.tolerance);
  set_default(al, "max_updates", d.augmented_lagrangian.max_updates);
  json& in = sub_object(out, "interface");
  set_default(in, "solver", name_of(d.interface.solver));
  set_default(in, "preconditioner", name_of(d.interface.preconditioner));
  set_default(in, "tolerance", d.interface.tolerance);
  set_default(in, "max_iterations", d.interface.max_iterations);
}

// The method and enforcement defaults depend on each other and on the adaptive strategy, so they are filled
// in after both sections are read; combinations that cannot run are errors here, never silent substitutes.
//  * method: interface_newton, except neumann under the paper's adaptive strategy (which is a Neumann
//    iteration interleaved with refinement);
//  * enforcement: exact for interface_newton and monolithic; penalty for neumann and robin (they iterate on the
//    penalty problem: exact is available to them only through augmented_lagrangian).
void JobReader::resolve_method_defaults() {
  SolverSettings& s = problem_.solver;
  json& out = sub_object(normalized_, "solver");
  const bool paper_strategy = problem_.adaptivity.enabled && problem_.adaptivity.strategy == AdaptStrategy::paper;
  const SolverSettings defaults;
  if (!method_.valid) s.method = paper_strategy ? Method::neumann : defaults.method;
  if (!enforcement_.valid)
    s.enforcement = iterates_on_penalty(s.method) || paper_strategy ? Enforcement::penalty : defaults.enforcement;
  if (paper_strategy && s.method != Method::neumann)
    errors_.add(method_.pointer.empty() ? "/adaptivity/strategy" : method_.pointer,
                std::string("the adaptive strategy \"paper\" interleaves single Neumann iterations (paper (16)-(17)) "
                            "with refinement: it needs method \"neumann\", not \"") +
                    to_string(s.method) +
                    "\" (or use strategy \"converge_then_refine\", which works with every method)");
  else if (paper_strategy && s.enforcement != Enforcement::penalty)
    errors_.add(enforcement_.pointer,
                "the adaptive strategy \"paper\" runs the paper's penalty iteration: enforcement must be \"penalty\" "
                "(use strategy \"converge_then_refine\" for exact or augmented-Lagrangian contact)");
  else if (const std::string conflict = settings_conflict(s); !conflict.empty())
    errors_.add(enforcement_.pointer, conflict);  // solve() refuses a Problem built in code with the same words
  set_default(out, "method", to_string(s.method));
  set_default(out, "enforcement", to_string(s.enforcement));
}

void JobReader::read_adaptivity(const json& value, const std::string& pointer) {
  Fields f(value, pointer, "adaptivity",
           {"indicator", "normalization", "delta", "marking", "grading", "bodies", "max_level", "max_dofs", "strategy",
            "max_steps", "stop_tolerance", "target_error"},
           errors_);
  if (!f.ok()) return;
  AdaptivitySettings& a = problem_.adaptivity;
  a.enabled = true;
  a.max_total_dofs = limits_.max_dofs;
  json& out = normalized_["adaptivity"];
  if (const json* i = f.find("indicator")) read_name(*i, f.at("indicator"), "indicator", a.indicator, errors_);
  if (const json* nz = f.find("normalization"))
    read_name(*nz, f.at("normalization"), "normalization", a.normalization, errors_);
  if (const json* d = f.find("delta"))
    if (auto x = positive(*d, f.at("delta"), "delta", errors_)) a.delta = *x;
  if (const json* mk = f.find("marking")) read_name(*mk, f.at("marking"), "marking", a.marking, errors_);
  if (const json* g = f.find("grading"))
    if (auto x = read::number(*g, f.at("grading"), "grading", errors_)) {
      if (*x < 0.0)
        errors_.add(f.at("grading"), "grading must be >= 0 (a cell size over a distance; 0 turns the limit off)");
      else
        a.grading = *x;
    }
  if (const json* l = f.find("max_level"))
    if (auto x = bounded_int(*l, f.at("max_level"), "max_level", 0, errors_)) {
      if (*x > 30)
        errors_.add(f.at("max_level"), "max_level = " + std::to_string(*x) + " is above 30");
      else
        a.max_level = *x;
    }
  if (const json* d = f.find("max_dofs"))
    if (auto x = bounded_int(*d, f.at("max_dofs"), "max_dofs", 1, errors_)) a.max_dofs = *x;
  if (const json* st = f.find("strategy")) read_name(*st, f.at("strategy"), "strategy", a.strategy, errors_);
  if (const json* n = f.find("max_steps"))
    if (auto x = bounded_int(*n, f.at("max_steps"), "max_steps", 1, errors_)) a.max_steps = *x;
  if (const json* t = f.find("stop_tolerance"))
    if (auto x = read::number(*t, f.at("stop_tolerance"), "stop_tolerance", errors_)) {
      if (*x < 0.0 || *x >= 1.0)
        errors_.add(f.at("stop_tolerance"),
                    "stop_tolerance must lie in [0, 1) (a relative change; 0 turns the test off)");
      else
        a.stop_tolerance = *x;
    }
  if (const json* b = f.find("bodies")) read_adaptive_bodies(*b, f.at("bodies"));
  if (const json* t = f.find("target_error"))
    read_target_error(*t, f.at("target_error"), f.find("stop_tolerance"), out);
  resolve_marking(f.find("marking") ? f.at("marking") : std::string(), f.find("delta") != nullptr,
                  f.find("max_level") != nullptr, f.find("max_steps") != nullptr, out);
  write_adaptivity_defaults(out);
}

// max_level with a target_error, max_steps with the goal-oriented marking (a target_error, or marking "goal"), where
// the job sets them (resolve_marking).
constexpr int kTargetMaxLevel = 12;
constexpr int kGoalMaxSteps = 30;

// "target_error": the estimated relative error of the contact pressure to reach (adapt/pressure_estimate.hpp).
// The estimate takes the fem_bem indicator's boundary-element solutions, and the loop it ends is
// converge_then_refine's; the stop test on the changes is off unless the job sets it (it would end the run at
// the changes of 0.5 %, before a finer target); max_level is 12 unless the job sets it (resolve_marking): the
// contact edges' share of the pressure error falls like their cells' size, and at level 8 it is ~0.08 % on the
// two-cylinder example, the floor of any finer target (docs/algorithm.md, "Refinement for the pressure's target").
void JobReader::read_target_error(const json& value, const std::string& pointer, const json* stop_tolerance,
                                  json& out) {
  AdaptivitySettings& a = problem_.adaptivity;
  const auto x = read::number(value, pointer, "target_error", errors_);
  if (!x) return;
  if (!(*x > 0.0 && *x < 1.0)) {
    errors_.add(pointer,
                "target_error must lie in (0, 1): the relative error of the contact pressure to reach "
                "(0.001 is 0.1 %)");
    return;
  }
  if (a.indicator != Indicator::fem_bem) {
    errors_.add(pointer,
                "target_error needs the fem_bem indicator (the pressure estimate takes its "
                "boundary-element solutions); remove \"indicator\": \"zz\" or the target");
    return;
  }
  if (a.strategy != AdaptStrategy::converge_then_refine) {
    errors_.add(pointer,
                "target_error needs the strategy \"converge_then_refine\" (the paper's strategy refines "
                "before each solve has converged, so no step has a pressure to estimate)");
    return;
  }
  if (problem_.solver.method == Method::monolithic) {
    errors_.add(pointer,
                "target_error needs a domain-decomposition method (the pressure estimate solves each body "
                "alone with its own factorisation, which the monolithic method does not build); use "
                "\"method\": \"interface_newton\" (the default) or remove the target");
    return;
  }
  a.target_error = *x;
  if (!stop_tolerance) {
    a.stop_tolerance = 0.0;
    out["stop_tolerance"] = 0.0;
  }
}

// The marking: "goal" (the pressure estimate's shares, as a target marks) by default where that estimate can be made
// (the fem_bem indicator, converge_then_refine, a domain-decomposition method) and the job gives no delta (a delta
// asks for the indicator's marking: "contact"); max_steps is then 30 unless the job sets it (a step adds a tenth to
// a half of the unknowns: the three examples of docs/job-format.md settle after 12-17 steps, where the indicator's
// marking doubles them a step). max_level is 12 with a target (the contact edges' share of the pressure error falls
// like their cells' size: read_target_error) and stays 8 without: a contact whose pressure is singular (a punch's
// corner) has a peak that grows with every level, and the goal marking refines it to the level limit; at 12 the
// punch under a force ran past 250k unknowns and 5 minutes, at 8 it settles in 21 s at 140k. A "goal" the job
// names where the
// estimate cannot be made is an error, never a silent substitute. `given`: the pointer of the job's "marking", or
// "" without one.
void JobReader::resolve_marking(const std::string& given, bool delta, bool max_level, bool max_steps, json& out) {
  AdaptivitySettings& a = problem_.adaptivity;
  std::string why_not;
  if (a.indicator != Indicator::fem_bem)
    why_not = "the fem_bem indicator (the pressure estimate takes its boundary-element solutions)";
  else if (a.strategy != AdaptStrategy::converge_then_refine)
    why_not = "the strategy \"converge_then_refine\" (the paper's strategy refines before each solve has converged)";
  else if (problem_.solver.method == Method::monolithic)
    why_not =
        "a domain-decomposition method (the pressure estimate solves each body alone, and the monolithic method "
        "factorises none)";
  if (!given.empty()) {
    if (a.marking == MarkingRule::goal && !why_not.empty())
      errors_.add(given, "marking \"goal\" needs " + why_not + "; use \"contact\" or \"plain\"");
  } else if (why_not.empty() && (!delta || a.target_error > 0.0)) {  // (a target marks so whatever the delta)
    a.marking = MarkingRule::goal;
    out["marking"] = name_of(a.marking);
  }
  const bool goal = a.marking == MarkingRule::goal || a.target_error > 0.0;
  if (a.target_error > 0.0 && !max_level) {
    a.max_level = kTargetMaxLevel;
    out["max_level"] = kTargetMaxLevel;
  }
  if (goal && !max_steps) {
    a.max_steps = kGoalMaxSteps;
    out["max_steps"] = kGoalMaxSteps;
  }
}

// "bodies": the names of the bodies to refine, as indices (each once).
void JobReader::read_adaptive_bodies(const json& value, const std::string& pointer) {
  AdaptivitySettings& a = problem_.adaptivity;
  if (!value.is_array()) {
    errors_.add(pointer, "bodies must be an array of body names, got " + read::type_name(value));
    return;
  }
  for (size_t i = 0; i < value.size(); ++i) {
    const std::string ip = child(pointer, i);
    if (!value[i].is_string()) {
      errors_.add(ip, "a body name must be a string, got " + read::type_name(value[i]));
      continue;
    }
    const std::string name = value[i].get<std::string>();
    int found = -1;
    std::vector<std::string> known;
    for (size_t k = 0; k < inputs_.size(); ++k) {
      if (inputs_[k].has_name && inputs_[k].body.name == name) found = static_cast<int>(k);
      if (inputs_[k].has_name) known.push_back(inputs_[k].body.name);
    }
    if (found < 0 && bodies_listed_ && bodies_all_named())  // else the bodies' own error is the cause
      errors_.add(ip, "unknown body '" + read::shown(name) + "'; the bodies are " + join_names(known));
    else if (std::find(a.bodies.begin(), a.bodies.end(), found) == a.bodies.end())
      a.bodies.push_back(found);
  }
}

// Every default of "adaptivity" into the normalized copy: AdaptivitySettings' own (bodies: all named ones).
void JobReader::write_adaptivity_defaults(json& out) {
  const AdaptivitySettings d;
  set_default(out, "indicator", name_of(d.indicator));
  set_default(out, "normalization", name_of(d.normalization));
  set_default(out, "delta", d.delta);
  set_default(out, "marking", name_of(d.marking));
  set_default(out, "grading", d.grading);
  if (!out.contains("bodies")) {
    json all = json::array();
    for (const auto& in : inputs_)
      if (in.has_name) all.push_back(in.body.name);
    out["bodies"] = all;
  }
  set_default(out, "max_level", d.max_level);
  set_default(out, "max_dofs", d.max_dofs);
  set_default(out, "strategy", name_of(d.strategy));
  set_default(out, "max_steps", d.max_steps);
  set_default(out, "stop_tolerance", d.stop_tolerance);
}

void JobReader::read_robin(const json& value, const std::string& pointer) {
  Fields f(value, pointer, "robin", {"psi"}, errors_);
  if (!f.ok()) return;
  if (const json* p = f.find("psi")) {
    if (p->is_string()) {
      if (p->get<std::string>() != "active_set")
        errors_.add(f.at("psi"), "psi must be a positive number or \"active_set\", got \"" +
                                     read::shown(p->get<std::string>()) + "\"");
    } else if (auto x = positive(*p, f.at("psi"), "psi", errors_)) {
      problem_.solver.robin.active_set = false;
      problem_.solver.robin.psi = *x;
    }
  }
}

void JobReader::read_augmented_lagrangian(const json& value, const std::string& pointer) {
  Fields f(value, pointer, "augmented_lagrangian", {"tolerance", "max_updates"}, errors_);
  if (!f.ok()) return;
  auto& al = problem_.solver.augmented_lagrangian;
  if (const json* t = f.find("tolerance"))
    if (auto x = positive(*t, f.at("tolerance"), "tolerance", errors_)) al.tolerance = *x;
  if (const json* n = f.find("max_updates"))
    if (auto x = bounded_int(*n, f.at("max_updates"), "max_updates", 1, errors_)) al.max_updates = *x;
}

void JobReader::read_interface_solver(const json& value, const std::string& pointer) {
  Fields f(value, pointer, "interface", {"solver", "preconditioner", "tolerance", "max_iterations"}, errors_);
  if (!f.ok()) return;
  auto& in = problem_.solver.interface;
  if (const json* v = f.find("solver")) read_name(*v, f.at("solver"), "solver", in.solver, errors_);
  if (const json* v = f.find("preconditioner"))
    read_name(*v, f.at("preconditioner"), "preconditioner", in.preconditioner, errors_);
  if (const json* t = f.find("tolerance")) {
    auto x = positive(*t, f.at("tolerance"), "tolerance", errors_);
    if (x && *x >= 1e-2)
      errors_.add(f.at("tolerance"),
                  "tolerance = " + format_number(*x) +
                      " is not below 0.01: the interface solver's tolerance is relative (1e-12 by default)");
    else if (x)
      in.tolerance = *x;
  }
  if (const json* n = f.find("max_iterations"))
    if (auto x = bounded_int(*n, f.at("max_iterations"), "max_iterations", 1, errors_)) in.max_iterations = *x;
}

void JobReader::read_penalty(const json& value, const std::string& pointer, json& out) {
  PenaltySpec& p = problem_.solver.penalty;
  Fields f(value, pointer, "penalty", {"theta", "c", "length"}, errors_);
  if (!f.ok()) return;
  if (f.has("theta") && (f.has("c") || f.has("length"))) {
    errors_.add(pointer, "give either theta, or c (with an optional length), not both: theta = c * length / E");
    return;
  }
  if (const json* t = f.find("theta")) {
    if (auto x = positive(*t, f.at("theta"), "theta", errors_)) p.theta = *x;
    return;
  }
  if (const json* c = f.find("c"))
    if (auto x = positive(*c, f.at("c"), "c", errors_)) p.c = *x;
  if (const json* l = f.find("length"))
    if (auto x = positive(*l, f.at("length"), "length", errors_)) p.length = *x;
  set_default(out, "c", PenaltySpec{}.c);
}

// "parallel": {"ranks": N}: the MPI ranks a server runs the job on (docs/parallel.md); contact-solve takes
// mpirun's number instead.
void JobReader::read_parallel(const Fields& top) {
  const int default_ranks = Problem{}.ranks;
  const json* v = top.find("parallel");
  if (!v) {
    set_default(normalized_, "parallel", json{{"ranks", default_ranks}});
    return;
  }
  Fields f(*v, top.at("parallel"), "parallel", {"ranks"}, errors_);
  if (!f.ok()) return;
  const json* n = f.find("ranks");
  if (!n) {
    if (normalized_.is_object() && normalized_["parallel"].is_object())
      normalized_["parallel"]["ranks"] = default_ranks;
    return;
  }
  if (auto x = bounded_int(*n, f.at("ranks"), "ranks", 1, errors_)) {
    if (*x > limits_.max_ranks) {
      errors_.add(f.at("ranks"), "ranks = " + std::to_string(*x) + " is more than the " +
                                     std::to_string(limits_.max_ranks) + " MPI ranks accepted here" +
                                     (limits_.ranks_hint.empty() ? "" : " (" + limits_.ranks_hint + ")"));
      return;
    }
    problem_.ranks = *x;
  }
}

// "loading": {"steps": N} (factors 1/N, 2/N, ..., 1) or {"factors": [f1, f2, ...]}.
void JobReader::read_loading(const Fields& top) {
  const json* v = top.find("loading");
  if (!v) {  // LoadingSpec's default: one step, the full load
    set_default(normalized_, "loading", json{{"steps", static_cast<int>(LoadingSpec{}.factors.size())}});
    return;
  }
  const std::string pointer = top.at("loading");
  const size_t before = errors_.size();
  read_loading_steps(*v, pointer);
  loading_read_ = errors_.size() == before;
}

void JobReader::read_loading_steps(const json& value, const std::string& pointer) {
  Fields f(value, pointer, "loading", {"steps", "factors"}, errors_);
  if (!f.ok()) return;
  if (f.has("steps") == f.has("factors")) {
    errors_.add(pointer, "give either steps (a number of equal load steps) or factors (the load factor of each step)");
    return;
  }
  std::vector<double> factors;
  if (const json* n = f.find("steps")) {
    if (auto x = bounded_int(*n, f.at("steps"), "steps", 1, errors_)) {
      if (*x > limits_.max_load_steps) {
        errors_.add(f.at("steps"), "steps = " + std::to_string(*x) + " is too large (at most " +
                                       std::to_string(limits_.max_load_steps) + "): each step is a whole solve");
        return;
      }
      for (int k = 1; k <= *x; ++k) factors.push_back(static_cast<double>(k) / *x);
    }
  } else if (const json* list = f.find("factors")) {
    if (!list->is_array() || list->empty()) {
      errors_.add(f.at("factors"),
                  "factors must be a non-empty array of positive numbers, got " + read::type_name(*list));
      return;
    }
    if (static_cast<long>(list->size()) > limits_.max_load_steps) {
      errors_.add(f.at("factors"), "factors has " + std::to_string(list->size()) + " entries: at most " +
                                       std::to_string(limits_.max_load_steps) + " load steps");
      return;
    }
    for (size_t k = 0; k < list->size(); ++k)
      if (auto x = positive((*list)[k], child(f.at("factors"), k), "load factor", errors_)) factors.push_back(*x);
  }
  if (factors.empty()) return;
  if (problem_.adaptivity.enabled && problem_.adaptivity.strategy == AdaptStrategy::paper && factors.size() > 1)
    errors_.add(pointer,
                "load steps with the adaptive strategy \"paper\" are not supported (it refines inside one "
                "solve): use strategy \"converge_then_refine\", which solves the path on each mesh");
  problem_.loading.factors = std::move(factors);
}

// {"steps": "last" | "all", "progress_pairs": [glob, ...], "iterate": bool}. steps: which steps' fields the result
// keeps. The default depends on the job (after adaptivity was read): an adaptive run's steps are ever finer meshes on
// the way to the answer, each about as large as the last, so only the last is kept; load steps are answers to different
// loads, kept all. progress_pairs: the pairs whose detail the progress lists (contact/progress_json.hpp), each
// pattern matching at least one pair (after the contacts were read). iterate: whether a step that did not converge
// keeps its last iterate (flagged); not by default (OutputSettings::iterate).
void JobReader::read_output(const Fields& top) {
  json& out = sub_object(normalized_, "output");
  problem_.output.steps = problem_.adaptivity.enabled ? StepOutput::last : OutputSettings{}.steps;
  if (const json* v = top.find("output")) {
    Fields f(*v, top.at("output"), "output", {"steps", "progress_pairs", "iterate"}, errors_);
    if (const json* s = f.find("steps")) read_name(*s, f.at("steps"), "steps", problem_.output.steps, errors_);
    if (const json* p = f.find("progress_pairs")) read_progress_pairs(*p, f.at("progress_pairs"));
    if (const json* i = f.find("iterate"))
      if (auto b = read::boolean(*i, f.at("iterate"), "iterate", errors_)) problem_.output.iterate = *b;
  }
  set_default(out, "steps", name_of(problem_.output.steps));
  set_default(out, "iterate", problem_.output.iterate);  // OutputSettings' default where not given
}

void JobReader::read_progress_pairs(const json& value, const std::string& pointer) {
  constexpr size_t kMaxPatterns = 16, kMaxPatternLength = 200;
  if (!value.is_array()) {
    errors_.add(pointer, "progress_pairs must be an array of pair names or patterns (* and ? as in a shell), got " +
                             read::type_name(value));
    return;
  }
  if (value.size() > kMaxPatterns) {
    errors_.add(pointer, "progress_pairs has " + std::to_string(value.size()) + " patterns: at most " +
                             std::to_string(kMaxPatterns) + " (one pattern such as \"b3_*\" selects many pairs)");
    return;
  }
  std::vector<std::string> names;
  for (const auto& c : problem_.contacts) names.push_back(c.name);
  for (size_t k = 0; k < value.size(); ++k) {
    const std::string at = child(pointer, k);
    const auto pattern = read::string(value[k], at, "a progress_pairs pattern", errors_);
    if (!pattern) continue;
    if (pattern->empty() || pattern->size() > kMaxPatternLength) {
      errors_.add(at, "a progress_pairs pattern must have 1 to " + std::to_string(kMaxPatternLength) +
                          " characters, not " + std::to_string(pattern->size()));
      continue;
    }
    if (auto problem = read::control_character_problem(*pattern, "the pattern")) {
      errors_.add(at, *problem);
      continue;
    }
    bool found = false;
    for (const auto& name : names) found = found || io::matches_any(name, {*pattern});
    if (!found && !names.empty()) {
      std::string listed;
      for (size_t n = 0; n < names.size() && n < 8; ++n) listed += (n ? ", " : "") + names[n];
      if (names.size() > 8) listed += ", ... (" + std::to_string(names.size()) + " pairs)";
      errors_.add(at, "'" + read::shown(*pattern) + "' matches no contact pair; the pairs are " + listed);
      continue;
    }
    problem_.output.progress_pairs.push_back(*pattern);
  }
}

}  // namespace contact::job::detail
