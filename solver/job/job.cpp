// The job format v1 (docs/job-format.md, api/job.schema.json): JSON -> Problem.
//
// Validation runs in phases so that every problem is reported at once and nothing expensive happens for a job
// that is already known to be bad:
//   1. read every field (types, ranges, unknown fields) without generating any mesh (a Gmsh mesh is read here,
//      its size bounded by the limit on degrees of freedom, since its edge names come from the file);
//   2. count the degrees of freedom from the mesh sizes alone and refuse the job if over the limit;
//   3. generate the meshes and check their cells;
//   4. check that each body is restrained against rigid motion (needs the mesh; only for bodies with no
//      other error, since a broken body would give a misleading answer);
//   5. resolve the contact pairs' references to bodies and edges.
// Problem::normalized is the submitted document with every default written in.
#include "job.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "gmsh_input.hpp"
#include "read.hpp"
#include "../fem/rigid_modes.hpp"

namespace contact::job {

namespace {

using nlohmann::json;
using read::child;
using read::Errors;
using read::Fields;
using read::format_number;
using read::join_names;
using Point = mesh::Point;

const char* const kBlockEdges[] = {"bottom", "right", "top", "left"};

// Writes a default into the normalized copy; a no-op where the copy is not an object (the job is bad then and
// the copy is never used).
void set_default(json& object, const std::string& key, json value) {
  if (object.is_object() && !object.contains(key)) object[key] = std::move(value);
}

// Letters, digits, '_' and '-' (and '.' when `dot`), at least one. A plain loop: std::regex_match recurses once
// per character and overflows the stack on a long name.
bool is_identifier(const std::string& s, bool dot = false) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [dot](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           (dot && c == '.');
  });
}

// Why `s` is not a name of at most `max_length` characters of the allowed set (the pattern quoted), or nullopt.
std::optional<std::string> name_problem(const std::string& s, const std::string& what, size_t max_length, bool dot) {
  const char* allowed = dot ? "letters, digits, '_', '-' and '.' only (pattern ^[A-Za-z0-9_.-]+$)"
                            : "letters, digits, '_' and '-' only (pattern ^[A-Za-z0-9_-]+$)";
  if (s.size() > max_length)
    return what + " '" + read::shown(s) + "' is too long: at most " + std::to_string(max_length) + " characters";
  if (!is_identifier(s, dot)) return what + " '" + read::shown(s) + "' must consist of " + allowed;
  return std::nullopt;
}

// Reads a name that other parts of the job refer to ("body.edge"), so it must be an identifier.
std::optional<std::string> identifier(const json& value, const std::string& pointer, const std::string& what,
                                      size_t max_length, Errors& errors) {
  auto s = read::string(value, pointer, what, errors);
  if (!s) return std::nullopt;
  if (auto problem = name_problem(*s, what, max_length, false)) {
    errors.add(pointer, *problem);
    return std::nullopt;
  }
  return s;
}

// A number that must be > 0.
std::optional<double> positive(const json& value, const std::string& pointer, const std::string& what, Errors& errors) {
  auto x = read::number(value, pointer, what, errors);
  if (x && !(*x > 0)) {
    errors.add(pointer, what + " = " + format_number(*x) + " must be positive");
    return std::nullopt;
  }
  return x;
}

// One of a fixed set of strings.
std::optional<std::string> choice(const json& value, const std::string& pointer, const std::string& what,
                                  const std::vector<std::string>& options, Errors& errors) {
  auto s = read::string(value, pointer, what, errors);
  if (!s) return std::nullopt;
  if (std::find(options.begin(), options.end(), *s) == options.end()) {
    std::vector<std::string> quoted;
    for (const auto& o : options) quoted.push_back("\"" + o + "\"");
    errors.add(pointer, what + " \"" + read::shown(*s) + "\" is not one of " + join_names(quoted));
    return std::nullopt;
  }
  return s;
}

// An integer in [min, max]; `max` defaults to what an int holds.
std::optional<int> bounded_int(const json& value, const std::string& pointer, const std::string& what, long long min,
                               Errors& errors, long long max = std::numeric_limits<int>::max()) {
  auto n = read::integer(value, pointer, what, errors);
  if (!n) return std::nullopt;
  if (*n < min) {
    errors.add(pointer, what + " = " + std::to_string(*n) + " must be at least " + std::to_string(min));
    return std::nullopt;
  }
  if (*n > max) {
    errors.add(pointer, what + " = " + std::to_string(*n) + " is too large (at most " + std::to_string(max) + ")");
    return std::nullopt;
  }
  return static_cast<int>(*n);
}

// Depth of a parsed document, without recursion (the document may be as deep as its producer liked).
int depth_of(const json& document) {
  int deepest = 0;
  std::vector<std::pair<const json*, int>> stack{{&document, 1}};
  while (!stack.empty()) {
    auto [value, depth] = stack.back();
    stack.pop_back();
    if (!value->is_structured()) continue;
    deepest = std::max(deepest, depth);
    if (deepest > read::kMaxDepth) return deepest;
    for (const auto& item : *value) stack.push_back({&item, depth + 1});
  }
  return deepest;
}

// ---------------------------------------------------------------------------------------------------------
// Phase 1 records: what was read of a body before any mesh exists.

struct MeshInput {
  enum class Kind { unknown, block, arrays, gmsh };
  Kind kind = Kind::unknown;
  bool valid = false;        // every field read without error: the mesh can be built
  double dofs = -1.0;        // 2 * nodes, known from the sizes alone; < 0 if unknown
  bool edges_known = false;  // the edge names are known (even if other fields are bad)
  std::vector<std::string> edge_names;
  std::vector<std::string> vertex_names;  // named vertices (a block's corners, an explicit mesh's "vertices")
  // block
  mesh::BlockSpec block;
  std::map<std::string, std::string> curve_pointers;  // edge name -> pointer of its curve object
  // explicit arrays
  std::vector<Point> nodes;
  std::vector<mesh::Cell> quads;
  std::vector<std::pair<std::string, std::vector<std::array<int, 2>>>> edge_pairs;
  std::map<std::string, int> vertices;  // named vertices of an explicit mesh: name -> node
  // gmsh: the surface's mesh, built while reading (gmsh_input.hpp)
  std::optional<GmshBody> gmsh;
};

struct BodyInput {
  std::string pointer;
  bool has_name = false;
  Body body;
  MeshInput mesh;
  std::vector<std::string> free_motions;  // rigid motions its displacement conditions leave free (a floating body)
};

bool has_edge(const MeshInput& m, const std::string& name) {
  return std::find(m.edge_names.begin(), m.edge_names.end(), name) != m.edge_names.end();
}

// For a Gmsh body: why `name`, a physical curve (or, for a vertex, a physical point) of the file, is not one of
// its edges (vertices); nullopt otherwise.
std::optional<std::string> gmsh_elsewhere(const MeshInput& m, const std::string& name, bool vertex = false) {
  if (!m.gmsh) return std::nullopt;
  const auto& other = vertex ? m.gmsh->points_elsewhere : m.gmsh->elsewhere;
  if (std::find(other.begin(), other.end(), name) == other.end()) return std::nullopt;
  if (vertex)
    return "physical point '" + name + "' is not on surface '" + m.gmsh->surface + "'; " +
           (m.vertex_names.empty() ? std::string("it has no physical points")
                                   : "the physical points on it are " + join_names(m.vertex_names));
  return "physical curve '" + name + "' is not on the boundary of surface '" + m.gmsh->surface +
         "'; the physical curves on its boundary are " + join_names(m.edge_names);
}

class JobReader {
 public:
  JobReader(const json& job, const Limits& limits) : job_(job), limits_(limits), normalized_(job), gmsh_(limits) {}

  ParseResult run() {
    Fields top(job_, "", "the job",
               {"name", "version", "model", "bodies", "contacts", "solver", "adaptivity", "loading", "parallel"}, errors_);
    if (!top.ok()) return finish();
    read_header(top);
    read_model(top);
    read_bodies(top);
    read_contacts(top);
    read_solver(top);
    if (const json* a = top.find("adaptivity")) read_adaptivity(*a, top.at("adaptivity"));
    read_loading(top);
    read_parallel(top);
    resolve_method_defaults();
    check_floating_bodies();
    check_work_limits();
    return finish();
  }

 private:
  // The upper bounds of Limits on the values read (a default is always within them). Separate from the readers so
  // that each bound is stated once, next to the others.
  void check_work_limits() {
    const SolverSettings& s = problem_.solver;
    auto over = [&](const std::string& pointer, const std::string& what, long long value, long long max,
                    const std::string& why) {
      if (value > max)
        errors_.add(pointer, what + " = " + std::to_string(value) + " is too large (at most " + std::to_string(max) +
                                 "): " + why);
    };
    over("/solver/threads", "threads", s.threads, limits_.max_threads,
         "each thread solves one body; 0 means one per body up to the cores");
    over("/solver/max_iterations", "max_iterations", s.max_iterations, limits_.max_iterations,
         "a job that needs more is not converging");
    over("/solver/augmented_lagrangian/max_updates", "max_updates", s.augmented_lagrangian.max_updates,
         limits_.max_updates, "each update runs a whole inner solve");
    if (problem_.adaptivity.enabled) {
      over("/adaptivity/max_steps", "max_steps", problem_.adaptivity.max_steps, limits_.max_adaptive_steps,
           "each step solves the whole problem again");
      over("/adaptivity/max_dofs", "max_dofs", problem_.adaptivity.max_dofs, limits_.max_dofs,
           "refinement may not exceed the server's limit on degrees of freedom");
    }
  }

  ParseResult finish() {
    ParseResult result;
    result.errors = errors_.take();
    if (result.errors.empty()) {
      for (auto& in : inputs_) problem_.bodies.push_back(std::move(in.body));
      problem_.submitted = job_;
      problem_.normalized = std::move(normalized_);
      result.problem = std::move(problem_);
    }
    return result;
  }

  void read_header(const Fields& top) {
    if (const json* v = top.find("name")) {
      if (auto s = read::string(*v, top.at("name"), "name", errors_)) {
        if (s->size() > limits_.max_job_name_length)
          errors_.add(top.at("name"), "name '" + read::shown(*s) + "' is too long: at most " +
                                          std::to_string(limits_.max_job_name_length) + " characters");
        else
          problem_.name = *s;
      }
    } else {
      problem_.name = "job";
    }
    set_default(normalized_, "name", "job");
    if (const json* v = top.find("version")) {
      auto n = read::integer(*v, top.at("version"), "version", errors_);
      if (n && *n != 1)
        errors_.add(top.at("version"),
                    "version " + std::to_string(*n) + " is not supported: this solver reads job format version 1");
    }
    set_default(normalized_, "version", 1);
  }

  void read_model(const Fields& top) {
    json& out = sub_object(normalized_, "model");
    if (const json* v = top.find("model")) {
      Fields f(*v, top.at("model"), "model", {"plane", "thickness"}, errors_);
      if (const json* p = f.find("plane")) {
        if (auto s = choice(*p, f.at("plane"), "plane", {"strain", "stress"}, errors_))
          problem_.model.plane = *s == "stress" ? Plane::stress : Plane::strain;
      }
      if (const json* t = f.find("thickness")) {
        if (auto x = positive(*t, f.at("thickness"), "thickness", errors_)) problem_.model.thickness = *x;
      }
    }
    set_default(out, "plane", "strain");
    set_default(out, "thickness", 1.0);
  }

  void read_solver(const Fields& top) {
    json& out = sub_object(normalized_, "solver");
    SolverSettings& s = problem_.solver;
    if (const json* v = top.find("solver")) {
      Fields f(*v, top.at("solver"), "solver",
               {"method", "penalty", "gamma", "tolerance", "criterion", "max_iterations", "initial_guess", "threads",
                "acceleration", "anderson_depth", "robin", "enforcement", "augmented_lagrangian"},
               errors_);
      if (const json* m = f.find("method")) {
        method_pointer_ = f.at("method");
        if (auto x = choice(*m, f.at("method"), "method", {"neumann", "monolithic", "interface_newton", "robin"}, errors_)) {
          s.method = *x == "monolithic"         ? Method::monolithic
                     : *x == "interface_newton" ? Method::interface_newton
                     : *x == "robin"            ? Method::robin
                                                : Method::neumann;
          method_given_ = true;
        }
      }
      if (const json* p = f.find("penalty")) read_penalty(*p, f.at("penalty"), sub_object(out, "penalty"));
      if (const json* g = f.find("gamma")) {
        if (g->is_string()) {
          if (g->get<std::string>() == "auto")
            s.gamma_auto = true;
          else
            errors_.add(f.at("gamma"), "gamma must be a number in (0, 2) or \"auto\", got \"" + g->get<std::string>() + "\"");
        } else {
          auto x = read::number(*g, f.at("gamma"), "gamma", errors_);
          if (x && !(*x > 0 && *x < 2))
            errors_.add(f.at("gamma"),
                        "gamma = " + format_number(*x) +
                            " is outside (0, 2): the relaxation weight must be greater than 0 and less than 2");
          else if (x) {
            s.gamma = *x;
            s.gamma_auto = false;
          }
        }
      }
      if (const json* t = f.find("tolerance"))
        if (auto x = positive(*t, f.at("tolerance"), "tolerance", errors_)) s.tolerance = *x;
      if (const json* c = f.find("criterion"))
        if (auto x = choice(*c, f.at("criterion"), "criterion", {"paper", "residual"}, errors_))
          s.criterion = *x == "residual" ? Criterion::residual : Criterion::paper;
      if (const json* n = f.find("max_iterations"))
        if (auto x = bounded_int(*n, f.at("max_iterations"), "max_iterations", 1, errors_)) s.max_iterations = *x;
      if (const json* g = f.find("initial_guess"))
        if (auto x = choice(*g, f.at("initial_guess"), "initial_guess", {"zero", "elastic_layer"}, errors_))
          s.initial_guess = *x == "zero" ? InitialGuess::zero : InitialGuess::elastic_layer;
      if (const json* t = f.find("threads"))
        if (auto x = bounded_int(*t, f.at("threads"), "threads", 0, errors_)) s.threads = *x;
      if (const json* a = f.find("acceleration"))
        if (auto x = choice(*a, f.at("acceleration"), "acceleration", {"none", "anderson"}, errors_))
          s.acceleration = *x == "anderson" ? Acceleration::anderson : Acceleration::none;
      if (const json* d = f.find("anderson_depth")) {
        if (auto x = bounded_int(*d, f.at("anderson_depth"), "anderson_depth", 1, errors_)) {
          if (*x > 50)
            errors_.add(f.at("anderson_depth"), "anderson_depth = " + std::to_string(*x) + " is above 50");
          else
            s.anderson_depth = *x;
        }
      }
      if (const json* r = f.find("robin")) read_robin(*r, f.at("robin"));
      if (const json* e = f.find("enforcement")) {
        enforcement_pointer_ = f.at("enforcement");
        if (auto x = choice(*e, f.at("enforcement"), "enforcement", {"exact", "penalty", "augmented_lagrangian"}, errors_)) {
          s.enforcement = *x == "augmented_lagrangian" ? Enforcement::augmented_lagrangian
                          : *x == "penalty"            ? Enforcement::penalty
                                                       : Enforcement::exact;
          enforcement_given_ = true;
        }
      }
      if (const json* a = f.find("augmented_lagrangian")) read_augmented_lagrangian(*a, f.at("augmented_lagrangian"));
    }
    set_default(out, "penalty", json{{"c", 0.05}});
    set_default(out, "gamma", "auto");
    set_default(out, "tolerance", 1e-8);
    set_default(out, "criterion", "residual");
    set_default(out, "max_iterations", 2000);
    set_default(out, "initial_guess", "elastic_layer");
    set_default(out, "threads", 0);
    set_default(out, "acceleration", "anderson");
    set_default(out, "anderson_depth", 10);
    set_default(out, "robin", json{{"psi", "active_set"}});
    set_default(out, "augmented_lagrangian", json{{"tolerance", 1e-6}, {"max_updates", 100}});
    json& al = out["augmented_lagrangian"];
    set_default(al, "tolerance", 1e-6);
    set_default(al, "max_updates", 100);
  }

  // The method and enforcement defaults depend on each other and on the adaptive strategy, so they are filled
  // in after both sections are read; combinations that cannot run are errors here, never silent substitutes.
  //  * method: interface_newton, except neumann under the paper's adaptive strategy (which is a Neumann
  //    iteration interleaved with refinement);
  //  * enforcement: exact for interface_newton and monolithic; penalty for neumann and robin (they iterate on the
  //    penalty problem: exact is available to them only through augmented_lagrangian).
  void resolve_method_defaults() {
    SolverSettings& s = problem_.solver;
    json& out = sub_object(normalized_, "solver");
    const bool paper_strategy = problem_.adaptivity.enabled && problem_.adaptivity.strategy == AdaptStrategy::paper;
    auto name = [](Method m) {
      return m == Method::neumann ? "neumann" : m == Method::robin ? "robin" : m == Method::monolithic ? "monolithic" : "interface_newton";
    };
    if (!method_given_) s.method = paper_strategy ? Method::neumann : Method::interface_newton;
    const bool fixed_point = s.method == Method::neumann || s.method == Method::robin;
    if (!enforcement_given_) s.enforcement = fixed_point || paper_strategy ? Enforcement::penalty : Enforcement::exact;
    if (paper_strategy && s.method != Method::neumann)
      errors_.add(method_pointer_.empty() ? "/adaptivity/strategy" : method_pointer_,
                  std::string("the adaptive strategy \"paper\" interleaves single Neumann iterations (paper (16)-(17)) "
                              "with refinement: it needs method \"neumann\", not \"") +
                      name(s.method) + "\" (or use strategy \"converge_then_refine\", which works with every method)");
    else if (paper_strategy && s.enforcement != Enforcement::penalty)
      errors_.add(enforcement_pointer_,
                  "the adaptive strategy \"paper\" runs the paper's penalty iteration: enforcement must be \"penalty\" "
                  "(use strategy \"converge_then_refine\" for exact or augmented-Lagrangian contact)");
    else if (fixed_point && s.enforcement == Enforcement::exact)
      errors_.add(enforcement_pointer_,
                  std::string("method \"") + name(s.method) +
                      "\" iterates on the penalty problem: enforcement \"exact\" is not available with it (use "
                      "\"penalty\", or \"augmented_lagrangian\" for exact contact in the limit, or method "
                      "\"interface_newton\")");
    set_default(out, "method", name(s.method));
    set_default(out, "enforcement", s.enforcement == Enforcement::exact     ? "exact"
                                    : s.enforcement == Enforcement::penalty ? "penalty"
                                                                            : "augmented_lagrangian");
  }

  void read_adaptivity(const json& value, const std::string& pointer) {
    Fields f(value, pointer, "adaptivity",
             {"indicator", "normalization", "delta", "bodies", "max_level", "max_dofs", "strategy", "max_steps"},
             errors_);
    if (!f.ok()) return;
    AdaptivitySettings& a = problem_.adaptivity;
    a.enabled = true;
    json& out = normalized_["adaptivity"];
    if (const json* i = f.find("indicator"))
      if (auto x = choice(*i, f.at("indicator"), "indicator", {"fem_bem", "zz"}, errors_))
        a.indicator = *x == "zz" ? Indicator::zz : Indicator::fem_bem;
    if (const json* nz = f.find("normalization"))
      if (auto x = choice(*nz, f.at("normalization"), "normalization", {"rms", "area"}, errors_))
        a.normalization = *x == "area" ? Normalization::area : Normalization::rms;
    if (const json* d = f.find("delta"))
      if (auto x = positive(*d, f.at("delta"), "delta", errors_)) a.delta = *x;
    if (const json* l = f.find("max_level"))
      if (auto x = bounded_int(*l, f.at("max_level"), "max_level", 0, errors_)) {
        if (*x > 30)
          errors_.add(f.at("max_level"), "max_level = " + std::to_string(*x) + " is above 30");
        else
          a.max_level = *x;
      }
    if (const json* d = f.find("max_dofs"))
      if (auto x = bounded_int(*d, f.at("max_dofs"), "max_dofs", 1, errors_)) a.max_dofs = *x;
    if (const json* st = f.find("strategy"))
      if (auto x = choice(*st, f.at("strategy"), "strategy", {"paper", "converge_then_refine"}, errors_))
        a.strategy = *x == "paper" ? AdaptStrategy::paper : AdaptStrategy::converge_then_refine;
    if (const json* n = f.find("max_steps"))
      if (auto x = bounded_int(*n, f.at("max_steps"), "max_steps", 1, errors_)) a.max_steps = *x;
    if (const json* b = f.find("bodies")) {
      const std::string bp = f.at("bodies");
      if (!b->is_array()) {
        errors_.add(bp, "bodies must be an array of body names, got " + read::type_name(*b));
      } else {
        for (size_t i = 0; i < b->size(); ++i) {
          const std::string ip = child(bp, i);
          if (!(*b)[i].is_string()) {
            errors_.add(ip, "a body name must be a string, got " + read::type_name((*b)[i]));
            continue;
          }
          const std::string name = (*b)[i].get<std::string>();
          int found = -1;
          std::string known;
          for (size_t k = 0; k < inputs_.size(); ++k) {
            if (inputs_[k].has_name && inputs_[k].body.name == name) found = static_cast<int>(k);
            if (inputs_[k].has_name) known += (known.empty() ? "" : ", ") + inputs_[k].body.name;
          }
          if (found < 0)
            errors_.add(ip, "unknown body '" + read::shown(name) + "'; the bodies are " + known);
          else if (std::find(a.bodies.begin(), a.bodies.end(), found) == a.bodies.end())
            a.bodies.push_back(found);
        }
      }
    }
    set_default(out, "indicator", "fem_bem");
    set_default(out, "normalization", "rms");
    set_default(out, "delta", 0.1);
    if (!out.contains("bodies")) {
      json all = json::array();
      for (const auto& in : inputs_)
        if (in.has_name) all.push_back(in.body.name);
      out["bodies"] = all;
    }
    set_default(out, "max_level", 8);
    set_default(out, "max_dofs", 400000);
    set_default(out, "strategy", "converge_then_refine");
    set_default(out, "max_steps", 20);
  }

  void read_robin(const json& value, const std::string& pointer) {
    Fields f(value, pointer, "robin", {"psi"}, errors_);
    if (!f.ok()) return;
    if (const json* p = f.find("psi")) {
      if (p->is_string()) {
        if (p->get<std::string>() != "active_set")
          errors_.add(f.at("psi"), "psi must be a positive number or \"active_set\", got \"" + p->get<std::string>() + "\"");
      } else if (auto x = positive(*p, f.at("psi"), "psi", errors_)) {
        problem_.solver.robin.active_set = false;
        problem_.solver.robin.psi = *x;
      }
    }
  }

  void read_augmented_lagrangian(const json& value, const std::string& pointer) {
    Fields f(value, pointer, "augmented_lagrangian", {"tolerance", "max_updates"}, errors_);
    if (!f.ok()) return;
    auto& al = problem_.solver.augmented_lagrangian;
    if (const json* t = f.find("tolerance"))
      if (auto x = positive(*t, f.at("tolerance"), "tolerance", errors_)) al.tolerance = *x;
    if (const json* n = f.find("max_updates"))
      if (auto x = bounded_int(*n, f.at("max_updates"), "max_updates", 1, errors_)) al.max_updates = *x;
  }

  void read_penalty(const json& value, const std::string& pointer, json& out) {
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
    set_default(out, "c", 0.05);
  }

  // ---- bodies --------------------------------------------------------------------------------------------

  void read_bodies(const Fields& top) {
    const json* list = top.require("bodies", "an array of at least one body");
    if (!list) return;
    if (!list->is_array()) {
      errors_.add("/bodies", "bodies must be an array, got " + read::type_name(*list));
      return;
    }
    if (list->empty()) {
      errors_.add("/bodies", "at least one body is required");
      return;
    }
    if (list->size() > static_cast<size_t>(limits_.max_bodies)) {  // refused before any body is read
      errors_.add("/bodies", "the job has " + std::to_string(list->size()) + " bodies; at most " +
                                 std::to_string(limits_.max_bodies) + " are accepted");
      return;
    }
    json& out_list = normalized_["bodies"];
    std::map<std::string, std::string> first_pointer_of_name;
    for (size_t i = 0; i < list->size(); ++i) {
      BodyInput in;
      in.pointer = child("/bodies", i);
      read_body((*list)[i], in, element(out_list, i));
      if (in.has_name) {
        auto [it, inserted] = first_pointer_of_name.emplace(in.body.name, in.pointer);
        if (!inserted)
          errors_.add(child(in.pointer, "name"),
                      "body name '" + in.body.name + "' is already used by " + it->second + "; names must be unique");
      }
      inputs_.push_back(std::move(in));
    }

    // Phase 2: the size limit, from the declared sizes alone, before anything is allocated.
    double total = 0.0;
    std::vector<std::string> parts;
    for (const auto& in : inputs_) {
      if (in.mesh.dofs < 0) continue;
      total += in.mesh.dofs;
      parts.push_back((in.has_name ? "'" + in.body.name + "'" : in.pointer) + " " + format_number(in.mesh.dofs));
    }
    if (total > static_cast<double>(limits_.max_dofs)) {
      errors_.add("/bodies", "the meshes would have " + format_number(total) + " degrees of freedom (" +
                                 join_names(parts) + "), more than the limit of " +
                                 format_number(static_cast<double>(limits_.max_dofs)));
      return;
    }

    // Phase 3: meshes; phase 4: rigid motion.
    for (auto& in : inputs_) {
      if (!in.mesh.valid) continue;
      build_mesh(in);
      if (errors_.count_under(in.pointer) == 0) {
        check_restrained(in);
        check_loads_reach_the_body(in);
      }
    }
  }

  void read_body(const json& value, BodyInput& in, json& out) {
    Fields f(value, in.pointer, "a body", {"name", "material", "mesh", "boundary", "body_force"}, errors_);
    if (!f.ok()) return;
    if (const json* n = f.require("name", "a name of letters, digits, '_' and '-', unique among the bodies"))
      if (auto s = identifier(*n, f.at("name"), "body name", limits_.max_name_length, errors_)) {
        in.body.name = *s;
        in.has_name = true;
      }
    if (const json* m = f.require("material", "an object {\"E\": Young's modulus, \"nu\": Poisson's ratio}"))
      read_material(*m, f.at("material"), in.body.material);
    if (const json* m = f.require("mesh", "one of {\"block\": {...}}, {\"nodes\": ..., \"quads\": ..., \"edges\": ...} "
                                          "or {\"gmsh\": {...}}"))
      read_mesh(*m, f.at("mesh"), in.mesh, sub_object(out, "mesh"));
    if (const json* b = f.find("boundary")) read_boundary(*b, f.at("boundary"), in);
    set_default(out, "boundary", json::array());
    if (const json* b = f.find("body_force"))
      if (auto v = read::pair(*b, f.at("body_force"), "body_force", errors_)) in.body.body_force = *v;
    set_default(out, "body_force", json::array({0.0, 0.0}));
  }

  void read_material(const json& value, const std::string& pointer, Material& material) {
    Fields f(value, pointer, "material", {"E", "nu"}, errors_);
    if (const json* e = f.require("E", "Young's modulus, a positive number"))
      if (auto x = read::number(*e, f.at("E"), "E", errors_)) {
        if (*x > 0)
          material.E = *x;
        else
          errors_.add(f.at("E"), "E = " + format_number(*x) + " must be positive (Young's modulus)");
      }
    if (const json* n = f.require("nu", "Poisson's ratio, a number in (-1, 0.5)"))
      if (auto x = read::number(*n, f.at("nu"), "nu", errors_)) {
        if (*x > -1 && *x < 0.5)
          material.nu = *x;
        else
          errors_.add(f.at("nu"),
                      "nu = " + format_number(*x) +
                          " is outside (-1, 0.5): Poisson's ratio must be greater than -1 and less than 0.5");
      }
  }

  void read_mesh(const json& value, const std::string& pointer, MeshInput& m, json& out) {
    if (!value.is_object()) {
      errors_.add(pointer, "mesh must be an object, got " + read::type_name(value));
      return;
    }
    if (value.contains("gmsh")) {
      const size_t before = errors_.size();
      Fields f(value, pointer, "mesh", {"gmsh"}, errors_);
      if (errors_.size() != before) {
        errors_.add(pointer, "give either a gmsh mesh, a block or explicit nodes and quads, not several");
        return;
      }
      read_gmsh(value.at("gmsh"), child(pointer, "gmsh"), m);
      return;
    }
    const bool block = value.contains("block");
    const bool arrays =
        value.contains("nodes") || value.contains("quads") || value.contains("edges") || value.contains("vertices");
    if (block == arrays) {
      Fields f(value, pointer, "mesh", {"block", "nodes", "quads", "edges", "vertices"}, errors_);
      errors_.add(pointer, block ? "give either a block or explicit nodes and quads, not both"
                                 : "give either {\"block\": {...}} or explicit \"nodes\" and \"quads\"");
      return;
    }
    if (block) {
      const size_t before = errors_.size();
      Fields f(value, pointer, "mesh", {"block"}, errors_);
      read_block(value.at("block"), child(pointer, "block"), m);
      m.valid = m.valid && errors_.size() == before;
    } else {
      read_arrays(value, pointer, m, out);
    }
  }

  void read_block(const json& value, const std::string& pointer, MeshInput& m) {
    m.kind = MeshInput::Kind::block;
    m.edges_known = true;
    m.edge_names = {"bottom", "right", "top", "left"};
    m.vertex_names = {"bottom_left", "bottom_right", "top_right", "top_left"};
    const size_t before = errors_.size();
    Fields f(value, pointer, "block", {"corners", "nx", "ny", "edges", "grading"}, errors_);
    if (!f.ok()) return;
    mesh::BlockSpec& spec = m.block;

    bool corners_ok = false;
    if (const json* c = f.require("corners", "four points [[x, y], ...] counter-clockwise, from the bottom-left")) {
      if (!c->is_array() || c->size() != 4) {
        errors_.add(f.at("corners"),
                    "corners must be an array of four points [x, y], got " +
                        (c->is_array() ? "an array of " + std::to_string(c->size()) : read::type_name(*c)));
      } else {
        corners_ok = true;
        for (size_t k = 0; k < 4; ++k) {
          auto p = read::pair((*c)[k], child(f.at("corners"), k), "corner " + std::to_string(k), errors_);
          if (p)
            spec.corners[k] = *p;
          else
            corners_ok = false;
        }
      }
    }
    if (corners_ok) {
      // Shoelace formula: positive for counter-clockwise corners.
      double area2 = 0.0;
      for (size_t k = 0; k < 4; ++k) {
        const Point& a = spec.corners[k];
        const Point& b = spec.corners[(k + 1) % 4];
        area2 += a.x() * b.y() - a.y() * b.x();
      }
      if (!(area2 > 0)) {
        errors_.add(f.at("corners"),
                    area2 < 0 ? "the corners run clockwise (signed area " + format_number(0.5 * area2) +
                                    "); list them counter-clockwise: bottom-left, bottom-right, top-right, top-left"
                              : "the corners enclose no area (signed area 0)");
        corners_ok = false;
      }
    }

    std::optional<long long> nx, ny;
    if (const json* v = f.require("nx", "the number of elements along the bottom edge, an integer >= 1"))
      nx = read_count(*v, f.at("nx"), "nx");
    if (const json* v = f.require("ny", "the number of elements along the left edge, an integer >= 1"))
      ny = read_count(*v, f.at("ny"), "ny");
    if (nx && ny) {
      m.dofs = 2.0 * (static_cast<double>(*nx) + 1.0) * (static_cast<double>(*ny) + 1.0);
      // make_block takes ints; anything larger is far beyond any DOF limit, but say so if the limit is huge.
      const long long int_max = std::numeric_limits<int>::max();
      if (*nx > int_max || *ny > int_max) {
        errors_.add(f.at(*nx > int_max ? "nx" : "ny"), "the block is too large to generate");
      } else {
        spec.nx = static_cast<int>(*nx);
        spec.ny = static_cast<int>(*ny);
      }
    }

    if (const json* e = f.find("edges")) {
      Fields edges(*e, f.at("edges"), "block edges", {"bottom", "right", "top", "left"}, errors_);
      for (const char* name : kBlockEdges)
        if (const json* c = edges.find(name)) read_curve(*c, edges.at(name), name, m);
    }

    if (const json* g = f.find("grading")) {
      Fields grading(*g, f.at("grading"), "grading", {"bottom", "right", "top", "left"}, errors_);
      for (const char* name : kBlockEdges)
        if (const json* r = grading.find(name))
          if (auto x = positive(*r, grading.at(name), std::string("grading ratio towards ") + name, errors_))
            spec.grading[name] = *x;
      if (grading.has("bottom") && grading.has("top"))
        errors_.add(f.at("grading"),
                    "grading towards both bottom and top: give at most one of them per direction "
                    "(the ratio grades the whole block from the named edge)");
      if (grading.has("left") && grading.has("right"))
        errors_.add(f.at("grading"),
                    "grading towards both left and right: give at most one of them per direction "
                    "(the ratio grades the whole block from the named edge)");
    }

    // Fit the curves to the corners they join (the order matches make_block's parametrisation).
    if (corners_ok) {
      const auto& P = spec.corners;
      const std::map<std::string, std::pair<Point, Point>> ends = {
          {"bottom", {P[0], P[1]}}, {"right", {P[1], P[2]}}, {"top", {P[3], P[2]}}, {"left", {P[0], P[3]}}};
      for (auto& [name, curve] : spec.curves) {
        const auto& [p, q] = ends.at(name);
        if (auto message = mesh::fit_curve(curve, p, q)) errors_.add(m.curve_pointers.at(name), *message);
      }
    }
    m.valid = errors_.size() == before;
  }

  // {"gmsh": {...}}: the file (or data) is read and the surface's mesh built here, so that its edge names are
  // known to the boundary conditions and contacts; its size counts in the limit like any other mesh's.
  void read_gmsh(const json& value, const std::string& pointer, MeshInput& m) {
    m.kind = MeshInput::Kind::gmsh;
    const size_t before = errors_.size();
    m.gmsh = gmsh_.read(value, pointer, errors_);
    if (!m.gmsh) return;
    for (const auto& name : m.gmsh->edges)
      if (auto problem = name_problem(name, "physical curve name", limits_.max_name_length, false))
        errors_.add(pointer, "surface '" + m.gmsh->surface + "': " + *problem + " to be used as an edge name");
    for (const auto& name : m.gmsh->vertices)
      if (auto problem = name_problem(name, "physical point name", limits_.max_name_length, false))
        errors_.add(pointer, "surface '" + m.gmsh->surface + "': " + *problem + " to be used as a vertex name");
    m.edges_known = true;
    m.edge_names = m.gmsh->edges;
    m.vertex_names = m.gmsh->vertices;
    m.dofs = 2.0 * m.gmsh->mesh.num_nodes();
    m.valid = errors_.size() == before;
  }

  std::optional<long long> read_count(const json& value, const std::string& pointer, const std::string& what) {
    auto n = read::integer(value, pointer, what, errors_);
    if (n && *n < 1) {
      errors_.add(pointer, what + " = " + std::to_string(*n) + " must be at least 1");
      return std::nullopt;
    }
    return n;
  }

  void read_curve(const json& value, const std::string& pointer, const std::string& edge, MeshInput& m) {
    Fields f(value, pointer, "the curve of edge " + edge, {"parabola", "arc"}, errors_);
    if (!f.ok()) return;
    if (f.has("parabola") == f.has("arc")) {
      errors_.add(pointer, "give exactly one of parabola {\"a\": ...} or arc {\"center\": [x, y], \"radius\": R}");
      return;
    }
    mesh::Curve curve;
    if (const json* p = f.find("parabola")) {
      Fields pf(*p, f.at("parabola"), "parabola", {"a"}, errors_);
      m.curve_pointers[edge] = f.at("parabola");
      curve.kind = mesh::Curve::Kind::parabola;
      const json* a = pf.require("a", "the coefficient a of y = a x^2 + b x + c (b and c follow from the corners)");
      if (!a) return;
      auto x = read::number(*a, pf.at("a"), "a", errors_);
      if (!x) return;
      curve.a = *x;
    } else {
      const json* arc = f.find("arc");
      Fields af(*arc, f.at("arc"), "arc", {"center", "radius"}, errors_);
      m.curve_pointers[edge] = f.at("arc");
      curve.kind = mesh::Curve::Kind::arc;
      const json* c = af.require("center", "the circle's centre [x, y]");
      const json* r = af.require("radius", "the circle's radius, a positive number");
      if (!c || !r) return;
      auto centre = read::pair(*c, af.at("center"), "center", errors_);
      auto radius = positive(*r, af.at("radius"), "radius", errors_);
      if (!centre || !radius) return;
      curve.center = *centre;
      curve.radius = *radius;
    }
    m.block.curves[edge] = curve;
  }

  void read_arrays(const json& value, const std::string& pointer, MeshInput& m, json& out) {
    m.kind = MeshInput::Kind::arrays;
    const size_t before = errors_.size();
    Fields f(value, pointer, "mesh", {"nodes", "quads", "edges", "vertices"}, errors_);
    const json* nodes = f.require("nodes", "an array of points [[x, y], ...], or use {\"block\": {...}}");
    const json* quads = f.require("quads", "an array of quads [[i, j, k, l], ...] (node indices, counter-clockwise)");
    size_t node_count = 0;
    const size_t before_nodes = errors_.size();
    if (nodes) {
      if (!nodes->is_array() || nodes->empty()) {
        errors_.add(f.at("nodes"), "nodes must be a non-empty array of points [x, y]");
      } else {
        node_count = nodes->size();
        m.dofs = 2.0 * static_cast<double>(node_count);
        // Keep reading the coordinates only while they might be used: a mesh over the DOF limit is refused anyway.
        if (m.dofs <= static_cast<double>(limits_.max_dofs)) {
          m.nodes.reserve(node_count);
          for (size_t k = 0; k < node_count; ++k) {
            auto p = read::pair((*nodes)[k], child(f.at("nodes"), k), "node " + std::to_string(k), errors_);
            m.nodes.push_back(p.value_or(Point::Zero()));
          }
        }
      }
    }
    // Indices are checked against the nodes only when those were read cleanly.
    const bool nodes_ok = nodes && node_count > 0 && errors_.size() == before_nodes;
    auto index = [&](const json& v, const std::string& ptr, const std::string& what) -> std::optional<int> {
      auto n = read::integer(v, ptr, what, errors_);
      if (!n) return std::nullopt;
      if (*n < 0 || *n >= static_cast<long long>(node_count)) {
        errors_.add(ptr, what + " = " + std::to_string(*n) + " is out of range: the mesh has " +
                             std::to_string(node_count) + " nodes, indices 0.." + std::to_string(node_count - 1));
        return std::nullopt;
      }
      return static_cast<int>(*n);
    };

    if (quads && nodes_ok) {
      if (!quads->is_array() || quads->empty()) {
        errors_.add(f.at("quads"), "quads must be a non-empty array of [i, j, k, l]");
      } else {
        for (size_t q = 0; q < quads->size(); ++q) {
          const json& quad = (*quads)[q];
          const std::string qp = child(f.at("quads"), q);
          if (!quad.is_array() || quad.size() != 4) {
            errors_.add(qp, "quad " + std::to_string(q) + " must be an array of four node indices [i, j, k, l]");
            continue;
          }
          mesh::Cell cell(-1, -1, -1, -1);
          bool ok = true;
          for (size_t k = 0; k < 4; ++k) {
            auto n = index(quad[k], child(qp, k), "node index");
            if (n)
              cell[k] = *n;
            else
              ok = false;
          }
          if (!ok) continue;
          std::set<int> distinct(cell.begin(), cell.end());
          if (distinct.size() != 4) {
            errors_.add(qp, "quad " + std::to_string(q) + " repeats a node: its four node indices must be distinct");
            continue;
          }
          m.quads.push_back(cell);
        }
      }
    }

    if (const json* e = f.find("edges")) {
      // Edge names are the user's own, so there is no fixed key set to check against.
      if (!e->is_object()) {
        errors_.add(f.at("edges"),
                    "edges must be an object {\"name\": [[i, j], ...], ...}, got " + read::type_name(*e));
      } else {
        m.edges_known = true;
        for (const auto& item : e->items())
          read_edge_set(item.key(), item.value(), child(f.at("edges"), item.key()), nodes_ok, index, m);
      }
    } else {
      m.edges_known = true;
      set_default(out, "edges", json::object());
    }
    // Named vertices {"name": node index}: where point loads and point supports go.
    if (const json* v = f.find("vertices")) {
      if (!v->is_object()) {
        errors_.add(f.at("vertices"),
                    "vertices must be an object {\"name\": node index, ...}, got " + read::type_name(*v));
      } else {
        for (const auto& item : v->items()) {
          const std::string vp = child(f.at("vertices"), item.key());
          if (auto problem = name_problem(item.key(), "vertex name", limits_.max_name_length, false)) {
            errors_.add(vp, *problem);
            continue;
          }
          m.vertex_names.push_back(item.key());
          if (!nodes_ok) continue;
          if (auto n = index(item.value(), vp, "vertex '" + item.key() + "' node index")) m.vertices[item.key()] = *n;
        }
      }
    } else {
      set_default(out, "vertices", json::object());
    }
    m.valid = errors_.size() == before && nodes_ok && !m.quads.empty();
  }

  // A side listed twice in one edge set (in either direction) would carry its load twice: an error at the
  // second listing, naming the first.
  bool no_side_twice(const std::string& name, const std::vector<std::array<int, 2>>& pairs,
                     const std::string& pointer) {
    std::map<std::pair<int, int>, size_t> first;
    bool ok = true;
    for (size_t k = 0; k < pairs.size(); ++k) {
      const auto [i, j] = pairs[k];
      auto [it, inserted] = first.emplace(std::make_pair(std::min(i, j), std::max(i, j)), k);
      if (inserted) continue;
      errors_.add(child(pointer, k), "the side [" + std::to_string(i) + ", " + std::to_string(j) + "] of edge '" +
                                         name + "' is already listed at " + child(pointer, it->second) +
                                         " (a side listed twice would carry its load twice)");
      ok = false;
    }
    return ok;
  }

  template <typename Index>
  void read_edge_set(const std::string& name, const json& value, const std::string& pointer, bool nodes_ok,
                     const Index& index, MeshInput& m) {
    if (auto problem = name_problem(name, "edge name", limits_.max_name_length, false)) {
      errors_.add(pointer, *problem);
      return;
    }
    m.edge_names.push_back(name);
    if (!value.is_array() || value.empty()) {
      errors_.add(pointer, "edge '" + name + "' must be a non-empty array of node pairs [[i, j], ...]");
      return;
    }
    if (!nodes_ok) return;
    std::vector<std::array<int, 2>> pairs;
    bool ok = true;
    for (size_t k = 0; k < value.size(); ++k) {
      const json& entry = value[k];
      const std::string pp = child(pointer, k);
      if (!entry.is_array() || entry.size() != 2) {
        errors_.add(pp, "an edge entry must be a pair of node indices [i, j]");
        ok = false;
        continue;
      }
      auto i = index(entry[0], child(pp, 0), "node index");
      auto j = index(entry[1], child(pp, 1), "node index");
      if (i && j)
        pairs.push_back({*i, *j});
      else
        ok = false;
    }
    if (ok) ok = no_side_twice(name, pairs, pointer);
    if (ok) m.edge_pairs.emplace_back(name, std::move(pairs));
  }

  void read_boundary(const json& value, const std::string& pointer, BodyInput& in) {
    if (!value.is_array()) {
      errors_.add(pointer, "boundary must be an array of conditions, got " + read::type_name(value));
      return;
    }
    std::map<std::string, std::string> first_pointer_of_place;
    for (size_t j = 0; j < value.size(); ++j) {
      const std::string bp = child(pointer, j);
      Fields f(value[j], bp, "a boundary condition", {"edge", "vertex", "displacement", "traction", "force", "free"},
               errors_);
      if (!f.ok()) continue;
      const size_t before = errors_.size();
      BoundaryCondition bc;
      if (f.has("edge") == f.has("vertex")) {
        errors_.add(bp, "give exactly one of edge (a named edge of the body) and vertex (a named vertex)");
        continue;
      }
      const bool at_vertex = f.has("vertex");
      const std::string place_key = at_vertex ? "vertex" : "edge";
      const std::vector<std::string>& names = at_vertex ? in.mesh.vertex_names : in.mesh.edge_names;
      if (const json* e = f.find(place_key))
        if (auto s = read::string(*e, f.at(place_key), place_key, errors_)) {
          (at_vertex ? bc.vertex : bc.edge) = *s;
          const bool known = std::find(names.begin(), names.end(), *s) != names.end();
          if (in.mesh.edges_known && !known) {
            const auto elsewhere = gmsh_elsewhere(in.mesh, *s, at_vertex);
            errors_.add(f.at(place_key),
                        elsewhere.value_or("the body has no " + place_key + " '" + read::shown(*s) + "'; " +
                                           (names.empty() ? std::string("it has no named ") + place_key + "s"
                                                          : "its " + std::string(at_vertex ? "vertices" : "edges") +
                                                                " are " + join_names(names))));
          } else {
            auto [it, inserted] = first_pointer_of_place.emplace(place_key + ":" + *s, bp);
            if (!inserted)
              errors_.add(f.at(place_key), place_key + " '" + *s + "' already has a condition at " + it->second +
                                               "; give each " + place_key +
                                               " one condition (displacement fixes only its given components)");
          }
        }
      const int loads = int(f.has("traction")) + int(f.has("force"));
      const int kinds = int(f.has("displacement")) + loads + int(f.has("free"));
      if (kinds == 0 || loads > 1 || (f.has("free") && kinds > 1)) {
        errors_.add(bp, "give a displacement, a load (traction or force), a displacement with a load on the other "
                        "component, or free");
        continue;
      }
      if (at_vertex && (f.has("traction") || f.has("free"))) {
        errors_.add(bp, "a vertex takes a displacement (a point support) or a force (a point load), not " +
                            std::string(f.has("traction") ? "a traction (a force per length)" : "free"));
        continue;
      }
      if (const json* d = f.find("displacement")) {
        bc.kind = BoundaryCondition::Kind::displacement;
        Fields df(*d, f.at("displacement"), "displacement", {"x", "y"}, errors_);
        if (df.ok() && !df.has("x") && !df.has("y"))
          errors_.add(f.at("displacement"), "give at least one of the components x and y");
        if (const json* x = df.find("x")) bc.ux = read::number(*x, df.at("x"), "displacement x", errors_);
        if (const json* y = df.find("y")) bc.uy = read::number(*y, df.at("y"), "displacement y", errors_);
        if (loads && bc.ux && bc.uy)
          errors_.add(bp, "both displacement components are prescribed: a load here would go straight into the support");
      }
      if (const json* t = f.find("traction")) {
        bc.kind = BoundaryCondition::Kind::traction;
        if (t->is_object()) {
          Fields tf(*t, f.at("traction"), "traction", {"normal"}, errors_);
          if (const json* p = tf.require("normal", "the normal pressure, positive pushing into the body")) {
            bc.normal_pressure = true;
            bc.pressure = read::number(*p, tf.at("normal"), "normal pressure", errors_).value_or(0.0);
          }
        } else if (t->is_array()) {
          if (auto v = read::pair(*t, f.at("traction"), "traction", errors_)) bc.traction = *v;
        } else {
          errors_.add(f.at("traction"),
                      "traction must be a vector [tx, ty] or {\"normal\": p}, got " + read::type_name(*t));
        }
      } else if (const json* fo = f.find("force")) {
        bc.kind = BoundaryCondition::Kind::force;
        if (auto v = read::pair(*fo, f.at("force"), "force", errors_)) bc.force = *v;
      } else if (f.has("free")) {
        bc.kind = BoundaryCondition::Kind::free;
        auto b = read::boolean(*f.find("free"), f.at("free"), "free", errors_);
        if (b && !*b) errors_.add(f.at("free"), "free must be true (an edge without a condition is free anyway)");
      }
      if (f.has("displacement") && bc.normal_pressure)
        errors_.add(bp, "a normal pressure cannot be combined with a displacement (part of it would go into the "
                        "support); give the traction as a vector [tx, ty] along the free component");
      // A load component along a prescribed displacement component would go straight into the support.
      const Eigen::Vector2d load = bc.kind == BoundaryCondition::Kind::force ? bc.force
                                   : bc.kind == BoundaryCondition::Kind::traction && !bc.normal_pressure ? bc.traction
                                                                                                         : Eigen::Vector2d::Zero();
      for (int c = 0; c < 2; ++c)
        if ((c == 0 ? bc.ux : bc.uy) && load[c] != 0.0)
          errors_.add(bp, std::string("the load's ") + (c == 0 ? "x" : "y") + " component acts where the " +
                              (c == 0 ? "x" : "y") + " displacement is prescribed: it would go straight into the support");
      if (errors_.size() == before) in.body.boundary.push_back(bc);
    }
  }

  void build_mesh(BodyInput& in) {
    const std::string mp = child(in.pointer, "mesh");
    MeshInput& m = in.mesh;
    mesh::Mesh& mesh = in.body.mesh;
    if (m.kind == MeshInput::Kind::block) {
      mesh = mesh::make_block(m.block);
    } else if (m.kind == MeshInput::Kind::gmsh) {
      mesh = std::move(m.gmsh->mesh);  // checked while reading (cells and edges, with Gmsh's element tags)
    } else {
      mesh.nodes = std::move(m.nodes);
      mesh.cells = std::move(m.quads);
      mesh.level.assign(mesh.cells.size(), 0);
      // An edge's order follows its cells' sides: only for valid cells (an inverted cell is the error to report).
      if (mesh::check_cells(mesh).empty())
        for (const auto& [name, pairs] : m.edge_pairs)
          if (auto message = mesh::add_edge_set(mesh, name, pairs))
            errors_.add(child(child(mp, "edges"), name), "edge '" + name + "': " + *message);
      mesh.vertices = std::move(m.vertices);
      check_arrays(mesh, mp);
    }
    // A bad curve can invert every cell of a block: report a few, then how many more, not thousands of lines.
    constexpr size_t kShown = 10;
    const auto problems = mesh::check_cells(mesh);
    for (size_t k = 0; k < std::min(problems.size(), kShown); ++k) errors_.add(mp, problems[k]);
    if (problems.size() > kShown)
      errors_.add(mp, "and " + std::to_string(problems.size() - kShown) + " more cells with the same kinds of problem");
  }

  // Explicit meshes only (a block is one piece by construction): every node belongs to a quad, and the quads
  // form one piece joined through shared sides. Either fault leaves the stiffness matrix singular.
  void check_arrays(const mesh::Mesh& mesh, const std::string& pointer) {
    std::vector<bool> used(mesh.nodes.size(), false);
    for (const auto& c : mesh.cells)
      for (int n : c) used[static_cast<size_t>(n)] = true;
    std::vector<std::string> unused;
    for (size_t n = 0; n < used.size(); ++n)
      if (!used[n]) unused.push_back(std::to_string(n));
    if (!unused.empty()) {
      if (unused.size() > 10) unused.resize(10), unused.push_back("...");
      errors_.add(child(pointer, "nodes"),
                  "nodes not used by any quad: " + join_names(unused) + " (each node must belong to a quad)");
    }
    const std::vector<int> piece = mesh::pieces(mesh);
    for (int c = 1; c < mesh.num_cells(); ++c)
      if (piece[static_cast<size_t>(c)] != 0) {
        errors_.add(child(pointer, "quads"), "quad " + std::to_string(c) +
                                                 " is not connected to quad 0 through shared sides: a body must be one "
                                                 "piece (use one body per piece)");
        return;
      }
  }

  // Phase 4: the rigid motions a body's displacement conditions leave free. A body that some are free for may
  // still be held by its contacts (check_floating_bodies decides, once the contacts and the method are known).
  void check_restrained(BodyInput& in) {
    const mesh::Mesh& mesh = in.body.mesh;
    std::set<fem::PrescribedDof> dofs;
    for (const auto& bc : in.body.boundary) {
      if (!prescribes_displacement(bc)) continue;
      for (int node : condition_nodes(mesh, bc)) {
        if (bc.ux) dofs.insert({node, 0});
        if (bc.uy) dofs.insert({node, 1});
      }
    }
    in.free_motions = fem::free_rigid_motions(mesh, std::vector<fem::PrescribedDof>(dofs.begin(), dofs.end()));
  }

  // A traction or force whose every node is held in both directions by displacement conditions would go straight
  // into the supports and move nothing: almost certainly a mistake in the job, so an error at that condition.
  void check_loads_reach_the_body(const BodyInput& in) {
    const mesh::Mesh& mesh = in.body.mesh;
    std::map<int, std::array<bool, 2>> held;
    for (const auto& bc : in.body.boundary) {
      if (!prescribes_displacement(bc)) continue;
      for (int node : condition_nodes(mesh, bc)) {
        held[node][0] = held[node][0] || bc.ux.has_value();
        held[node][1] = held[node][1] || bc.uy.has_value();
      }
    }
    for (size_t j = 0; j < in.body.boundary.size(); ++j) {
      const auto& bc = in.body.boundary[j];
      if (bc.kind != BoundaryCondition::Kind::force && bc.kind != BoundaryCondition::Kind::traction) continue;
      const auto nodes = condition_nodes(mesh, bc);
      const bool all_held = !nodes.empty() && std::all_of(nodes.begin(), nodes.end(), [&](int node) {
        auto it = held.find(node);
        return it != held.end() && it->second[0] && it->second[1];
      });
      if (all_held)
        errors_.add(child(child(in.pointer, "boundary"), j),
                    std::string("the ") + (bc.kind == BoundaryCondition::Kind::force ? "force" : "traction") + " on " +
                        (bc.vertex.empty() ? "edge '" + bc.edge + "'" : "vertex '" + bc.vertex + "'") +
                        " acts only on nodes whose displacement is prescribed in both directions: it would go "
                        "straight into the supports and load nothing");
    }
  }

  // A floating body (free rigid motions) is accepted when it touches another body and the method solves the
  // interface problem with its equilibrium (interface_newton, monolithic); the fixed-point schemes solve every
  // body alone with Neumann data on its contact zone, which a floating body cannot take.
  void check_floating_bodies() {
    const Method method = problem_.solver.method;
    for (size_t i = 0; i < inputs_.size(); ++i) {
      const BodyInput& in = inputs_[i];
      if (in.free_motions.empty()) continue;
      const std::string free = join_names(in.free_motions) + (in.free_motions.size() == 1 ? " is" : " are") + " free";
      bool in_contact = false;
      for (const auto& c : problem_.contacts)
        in_contact = in_contact || c.slave_body == static_cast<int>(i) || c.master_body == static_cast<int>(i);
      if (!in_contact) {
        errors_.add(child(in.pointer, "boundary"),
                    "body '" + in.body.name + "' is not restrained against rigid motion (" + free +
                        ") and touches no other body: prescribe a displacement component on one of its edges or "
                        "vertices, or give it a contact that can hold it");
      } else if (method == Method::neumann || method == Method::robin) {
        errors_.add(method_pointer_.empty() ? child(in.pointer, "boundary") : method_pointer_,
                    "body '" + in.body.name + "' floats (" + free + ": only its contacts hold it), and method \"" +
                        (method == Method::neumann ? "neumann" : "robin") +
                        "\" solves every body on its own with contact tractions as loads, which a floating body "
                        "cannot take; use method \"interface_newton\" (the default) or \"monolithic\", or restrain "
                        "the body");
      }
    }
  }

  // "parallel": {"ranks": N}: the MPI ranks a server runs the job on (docs/parallel.md); contact-solve takes
  // mpirun's number instead.
  void read_parallel(const Fields& top) {
    const json* v = top.find("parallel");
    if (!v) {
      set_default(normalized_, "parallel", json{{"ranks", 1}});
      return;
    }
    Fields f(*v, top.at("parallel"), "parallel", {"ranks"}, errors_);
    if (!f.ok()) return;
    const json* n = f.find("ranks");
    if (!n) {
      if (normalized_.is_object() && normalized_["parallel"].is_object()) normalized_["parallel"]["ranks"] = 1;
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
  void read_loading(const Fields& top) {
    const json* v = top.find("loading");
    if (!v) {
      set_default(normalized_, "loading", json{{"steps", 1}});
      return;
    }
    const std::string pointer = top.at("loading");
    Fields f(*v, pointer, "loading", {"steps", "factors"}, errors_);
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
        errors_.add(f.at("factors"), "factors must be a non-empty array of positive numbers, got " + read::type_name(*list));
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
    if (problem_.adaptivity.enabled && factors.size() > 1)
      errors_.add(pointer, "load steps and adaptivity together are not supported: refine for one load, or step a "
                           "fixed mesh");
    problem_.loading.factors = std::move(factors);
  }

  // ---- contacts ------------------------------------------------------------------------------------------

  struct EdgeRef {
    int body = -1;
    std::string edge;
  };

  // "body.edge" -> indices; reports what is wrong at `pointer`.
  std::optional<EdgeRef> resolve(const json& value, const std::string& pointer, const std::string& what) {
    auto s = read::string(value, pointer, what, errors_);
    if (!s) return std::nullopt;
    const size_t dot = s->find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == s->size() || s->find('.', dot + 1) != std::string::npos) {
      errors_.add(pointer, what + " must be \"body.edge\" (e.g. \"upper.bottom\"), got \"" + read::shown(*s) + "\"");
      return std::nullopt;
    }
    const std::string body = s->substr(0, dot), edge = s->substr(dot + 1);
    std::vector<std::string> names;
    for (size_t b = 0; b < inputs_.size(); ++b) {
      if (inputs_[b].has_name) names.push_back(inputs_[b].body.name);
      if (inputs_[b].has_name && inputs_[b].body.name == body) {
        const MeshInput& m = inputs_[b].mesh;
        if (m.edges_known && !has_edge(m, edge)) {
          errors_.add(pointer, gmsh_elsewhere(m, edge).value_or("body '" + body + "' has no edge '" + read::shown(edge) +
                                                                 "'; its edges are " + join_names(m.edge_names)));
          return std::nullopt;
        }
        return EdgeRef{static_cast<int>(b), edge};
      }
    }
    errors_.add(pointer, "there is no body named '" + read::shown(body) + "'; the bodies are " + join_names(names));
    return std::nullopt;
  }

  void read_contacts(const Fields& top) {
    json& out_list = sub_object(normalized_, "contacts");
    const json* list = top.find("contacts");
    if (!list) {
      out_list = json::array();
      return;
    }
    if (!list->is_array()) {
      errors_.add("/contacts", "contacts must be an array, got " + read::type_name(*list));
      return;
    }
    if (list->size() > static_cast<size_t>(limits_.max_contacts)) {  // refused before any pair is read
      errors_.add("/contacts", "the job has " + std::to_string(list->size()) + " contact pairs; at most " +
                                   std::to_string(limits_.max_contacts) + " are accepted");
      return;
    }
    std::map<std::string, std::string> pointer_of_name;
    std::map<std::pair<std::string, std::string>, std::string> pointer_of_pair;
    for (size_t k = 0; k < list->size(); ++k) {
      const std::string cp = child("/contacts", k);
      json& out = element(out_list, k);
      Fields f((*list)[k], cp, "a contact", {"name", "slave", "master", "gap"}, errors_);
      if (!f.ok()) continue;
      const size_t before = errors_.size();
      ContactPair pair;
      std::optional<EdgeRef> slave, master;
      if (const json* s = f.require("slave", "the edge integrated over, \"body.edge\""))
        slave = resolve(*s, f.at("slave"), "slave");
      if (const json* m = f.require("master", "the edge projected on, \"body.edge\""))
        master = resolve(*m, f.at("master"), "master");
      if (slave && master) {
        const std::string s = f.find("slave")->get<std::string>(), m = f.find("master")->get<std::string>();
        pair.slave_body = slave->body;
        pair.slave_edge = slave->edge;
        pair.master_body = master->body;
        pair.master_edge = master->edge;
        pair.name = s + "-" + m;
        if (slave->body == master->body) {
          errors_.add(cp, "a body cannot be in contact with itself (slave " + s + ", master " + m + ")");
        } else if (auto it = pointer_of_pair.find({s, m}); it != pointer_of_pair.end()) {
          errors_.add(cp, "the pair " + s + " -> " + m + " is already given at " + it->second);
        } else if (auto swapped = pointer_of_pair.find({m, s}); swapped != pointer_of_pair.end()) {
          errors_.add(
              cp, "the pair " + s + " -> " + m + " is already given, slave and master swapped, at " + swapped->second);
        } else {
          pointer_of_pair.emplace(std::make_pair(s, m), cp);
        }
      }
      if (const json* n = f.find("name")) {
        auto s = read::string(*n, f.at("name"), "contact name", errors_);
        // Room for the default name, "body.edge-body.edge" (four identifiers).
        auto problem = s ? name_problem(*s, "contact name", 4 * limits_.max_name_length + 3, true) : std::nullopt;
        if (problem)
          errors_.add(f.at("name"), *problem);
        else if (s)
          pair.name = *s;
      }
      if (!pair.name.empty()) {
        auto [it, inserted] = pointer_of_name.emplace(pair.name, cp);
        if (!inserted)
          errors_.add(f.has("name") ? f.at("name") : cp,
                      "contact name '" + pair.name + "' is already used by " + it->second + "; names must be unique");
        set_default(out, "name", pair.name);
      }
      read_gap(f, pair.gap, sub_object(out, "gap"));
      if (errors_.size() == before) problem_.contacts.push_back(pair);
    }
  }

  void read_gap(const Fields& contact, GapSpec& gap, json& out) {
    if (const json* g = contact.find("gap")) {
      Fields f(*g, contact.at("gap"), "gap", {"geometric", "constant", "parabola"}, errors_);
      if (const json* v = f.find("geometric"))
        if (auto b = read::boolean(*v, f.at("geometric"), "geometric", errors_)) gap.geometric = *b;
      if (const json* v = f.find("constant"))
        if (auto x = read::number(*v, f.at("constant"), "constant", errors_)) gap.constant = *x;
      if (const json* p = f.find("parabola")) {
        Fields pf(*p, f.at("parabola"), "parabola", {"r0", "x0"}, errors_);
        if (const json* r = pf.require("r0", "the coefficient r0 of the added gap r0 (x - x0)^2"))
          gap.parabola_r0 = read::number(*r, pf.at("r0"), "r0", errors_);
        if (const json* x0 = pf.find("x0"))
          if (auto x = read::number(*x0, pf.at("x0"), "x0", errors_)) gap.parabola_x0 = *x;
        set_default(sub_object(out, "parabola"), "x0", 0.0);
      }
    }
    set_default(out, "geometric", true);
    set_default(out, "constant", 0.0);
  }

  // The normalized counterpart of a sub-object, created as {} if absent. Where the submitted value has the
  // wrong type the job is already in error, and a throw-away value stands in so that reading can go on.
  json& sub_object(json& parent, const std::string& key) {
    if (!parent.is_object()) return discard();
    if (!parent.contains(key)) parent[key] = json::object();
    return parent[key];
  }
  json& element(json& array, size_t index) {
    if (!array.is_array() || index >= array.size()) return discard();
    return array[index];
  }
  json& discard() {
    discarded_ = json::object();
    return discarded_;
  }

  const json& job_;
  const Limits& limits_;
  json normalized_;
  json discarded_;
  Errors errors_;
  Problem problem_;
  bool method_given_ = false, enforcement_given_ = false;
  std::string method_pointer_, enforcement_pointer_ = "/solver";
  std::vector<BodyInput> inputs_;
  GmshMeshes gmsh_;
};

// Nesting depth of JSON text, found by scanning brackets outside strings, so that a hostile document is refused
// before any parser (or destructor) walks it. Returns the 1-based byte at which kMaxDepth is exceeded.
std::optional<size_t> too_deep_at(const std::string& text) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (size_t k = 0; k < text.size(); ++k) {
    const char ch = text[k];
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (ch == '\\')
        escaped = true;
      else if (ch == '"')
        in_string = false;
    } else if (ch == '"') {
      in_string = true;
    } else if (ch == '[' || ch == '{') {
      if (++depth > read::kMaxDepth) return k + 1;
    } else if (ch == ']' || ch == '}') {
      --depth;
    }
  }
  return std::nullopt;
}

// Follows the parser through the document (as its callback) so that problems only the text shows can be put at
// a pointer: duplicate keys in one object (nlohmann keeps the last silently, which would hide a mistake), and
// the value being read when parsing stops (a number that overflows a double).
class TextPath {
 public:
  explicit TextPath(Errors& errors) : errors_(errors) {}

  bool on_event(json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        count_element();
        frames_.push_back({event == json::parse_event_t::object_start, {}, {}, -1});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!frames_.empty()) frames_.pop_back();
        break;
      case json::parse_event_t::key:
        if (!frames_.empty() && parsed.is_string()) {
          Frame& f = frames_.back();
          f.key = parsed.get<std::string>();
          if (!f.keys.insert(f.key).second)
            errors_.add(pending_pointer(),
                        "duplicate key '" + read::shown(f.key) + "' in one object (a JSON reader keeps only one of them)");
        }
        break;
      case json::parse_event_t::value:
        count_element();
        break;
    }
    return true;
  }

  // The pointer of the value the parser is reading now (after its key, or as the next element of an array).
  std::string pending_pointer() const {
    std::string p;
    for (size_t k = 0; k < frames_.size(); ++k) {
      const Frame& f = frames_[k];
      const bool innermost = k + 1 == frames_.size();
      // An array's index counts the elements started so far; the innermost one's pending element is the next.
      p = f.object ? child(p, f.key) : child(p, static_cast<size_t>(std::max(0L, f.index + (innermost ? 1 : 0))));
    }
    return p;
  }
  // The name of that value for messages: its key, or "element i".
  std::string pending_name() const {
    if (frames_.empty()) return "the value";
    const Frame& f = frames_.back();
    return f.object ? f.key : "element " + std::to_string(f.index + 1);
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;
    long index;
  };
  void count_element() {
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
  }
  Errors& errors_;
  std::vector<Frame> frames_;
};

ParseResult failure(const std::string& pointer, const std::string& message) {
  ParseResult r;
  r.errors.push_back({pointer, message});
  return r;
}

}  // namespace

ParseResult parse(const json& job, const Limits& limits) {
  try {
    if (depth_of(job) > read::kMaxDepth)
      return failure("", "the document is nested deeper than " + std::to_string(read::kMaxDepth) + " levels");
    return JobReader(job, limits).run();
  } catch (const std::exception& e) {
    return failure("", std::string("internal error while reading the job: ") + e.what());
  } catch (...) {
    return failure("", "internal error while reading the job");
  }
}

ParseResult parse_text(const std::string& text, const Limits& limits) {
  try {
    if (auto at = too_deep_at(text))
      return failure("", "the document is nested deeper than " + std::to_string(read::kMaxDepth) + " levels (at byte " +
                             std::to_string(*at) + ")");
    Errors text_errors;
    TextPath path(text_errors);
    json job;
    try {
      job = json::parse(text, [&path](int /*depth*/, json::parse_event_t event, json& parsed) {
        return path.on_event(event, parsed);
      });
    } catch (const json::parse_error& e) {
      // e.what() reads "[json.exception.parse_error.101] parse error at line 1, column 5: ..."; drop the tag.
      std::string detail = e.what();
      if (auto close = detail.find("] "); detail.rfind("[json.exception", 0) == 0 && close != std::string::npos)
        detail = detail.substr(close + 2);
      return failure("", "malformed JSON at byte " + std::to_string(e.byte) + ": " + detail);
    } catch (const json::out_of_range& e) {
      // nlohmann stops at a number too large for a double (406) instead of reading it as infinity.
      std::string number;
      const std::string what = e.what();
      if (auto open = what.find('\''), close = what.rfind('\''); open != std::string::npos && close > open)
        number = " (" + what.substr(open + 1, close - open - 1) + " overflows a double)";
      return failure(path.pending_pointer(), path.pending_name() + " must be a finite number" + number);
    }
    ParseResult result = parse(job, limits);
    if (text_errors.size() > 0) {
      auto errors = text_errors.take();
      errors.insert(errors.end(), result.errors.begin(), result.errors.end());
      result.errors = std::move(errors);
      result.problem.reset();
    }
    return result;
  } catch (const std::exception& e) {
    return failure("", std::string("internal error while reading the job: ") + e.what());
  } catch (...) {
    return failure("", "internal error while reading the job");
  }
}

ParseResult parse_file(const std::string& path, Limits limits) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  if (!in) return failure("", "cannot open the job file '" + path + "': " + std::strerror(errno));
  text << in.rdbuf();  // an empty file leaves the text empty: malformed JSON, said by parse_text
  limits.mesh_directory = job_directory(path);
  return parse_text(text.str(), limits);
}

std::string job_directory(const std::string& path) {
  const std::filesystem::path directory = std::filesystem::path(path).parent_path();
  return directory.empty() ? std::string(".") : directory.string();
}

std::string format_errors(const std::vector<ValidationError>& errors) {
  std::string out;
  for (const auto& e : errors)
    out += (e.pointer.empty() ? std::string("(document)") : e.pointer) + ": " + e.message + "\n";
  return out;
}

}  // namespace contact::job
