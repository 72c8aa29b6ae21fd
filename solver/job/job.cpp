// The job format v1 (docs/job-format.md, api/job.schema.json): JSON -> Problem. The entry points of job.hpp, the
// checks on the text before it is parsed, and the frame of the reader (job_reader.hpp, which says how validation
// runs in phases): run, the header, the model, the limits on work and the normalized copy.
#include "contact/job.hpp"
#include "contact/result_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../check/initial_gaps.hpp"
#include "job_reader.hpp"
#include "names.hpp"
#include "read.hpp"

namespace contact::job {

namespace detail {

void set_default(json& object, const std::string& key, json value) {
  if (object.is_object() && !object.contains(key)) object[key] = std::move(value);
}

ParseResult JobReader::run() {
  Fields top(job_, "", "the job",
             {"name", "version", "model", "meshes", "bodies", "contacts", "solver", "adaptivity", "loading", "collapse",
              "parallel", "output", "strict", "warnings"},
             errors_);
  if (!top.ok()) return finish();
  read_header(top);
  read_strict(top);
  read_model(top);
  if (const json* m = top.find("meshes"))
    gmsh_.read_table(*m, top.at("meshes"), errors_, sub_object(normalized_, "meshes"));
  read_bodies(top);
  if (out_of_time("reading the bodies and building their meshes")) return finish();
  if (!inputs_.empty()) gmsh_.check_table_used(errors_);  // not when the bodies could not be read at all
  read_contacts(top);
  if (out_of_time("reading the contact pairs")) return finish();
  check_pairs_face();
  if (out_of_time("checking that the pairs' edges face each other")) return finish();
  read_solver(top);
  if (const json* a = top.find("adaptivity")) read_adaptivity(*a, top.at("adaptivity"));
  read_loading(top);
  read_collapse(top);
  read_output(top);
  read_parallel(top);
  resolve_method_defaults();
  check_friction_and_histories();
  check_collapse();
  check_floating_bodies();
  if (out_of_time("checking the floating bodies")) return finish();
  check_work_limits();
  return finish();
}

bool JobReader::out_of_time(const char* during) {
  if (timed_out_) return true;
  if (limits_.max_validation_seconds <= 0) return false;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  if (seconds <= limits_.max_validation_seconds) return false;
  timed_out_ = true;
  char text[160];
  std::snprintf(text, sizeof text, "validation took %.3g s (stopped while %s), more than the %g s allowed", seconds,
                during, limits_.max_validation_seconds);
  errors_.add("", std::string(text) +
                      (limits_.validation_seconds_hint.empty() ? "" : " (" + limits_.validation_seconds_hint + ")") +
                      ": the job is larger than this server validates; split it, or take coarser meshes");
  return true;
}

// The upper bounds of Limits on the values read (a default is always within them). Separate from the readers so
// that each bound is stated once, next to the others.
void JobReader::check_work_limits() {
  const SolverSettings& s = problem_.solver;
  auto over = [&](const std::string& pointer, const std::string& what, long long value, long long max,
                  const std::string& why) {
    if (value > max)
      errors_.add(pointer,
                  what + " = " + std::to_string(value) + " is too large (at most " + std::to_string(max) + "): " + why);
  };
  over("/solver/threads", "threads", s.threads, limits_.max_threads,
       "each thread solves one body; 0 means one per body up to the cores");
  over("/solver/max_iterations", "max_iterations", s.max_iterations, limits_.max_iterations,
       "a job that needs more is not converging");
  over("/solver/augmented_lagrangian/max_updates", "max_updates", s.augmented_lagrangian.max_updates,
       limits_.max_updates, "each update runs a whole inner solve");
  check_result_size();
  check_interface_memory();
  if (problem_.adaptivity.enabled) {
    over("/adaptivity/max_steps", "max_steps", problem_.adaptivity.max_steps, limits_.max_adaptive_steps,
         "each step solves the whole problem again");
    over("/adaptivity/max_dofs", "max_dofs", problem_.adaptivity.max_dofs, limits_.max_dofs,
         "refinement may not exceed the server's limit on degrees of freedom");
  }
}

namespace {

std::string size(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, bytes >= 1e9 ? "%.3g GB" : "%.3g MB", bytes >= 1e9 ? bytes / 1e9 : bytes / 1e6);
  return text;
}

}  // namespace

// The result's size (and the memory its kept steps take until written) from the meshes' nodes and the steps kept:
// every load step with output.steps "all". An adaptive run's meshes are made as it runs: its first must fit, and
// it refines within what the limit leaves (AdaptivitySettings::max_kept_nodes). A job's unknowns times its load steps
// had no bound: 1000 load steps of two 100 x 100 blocks wrote 5.15 GB and held 2.3 GB in the server after they were
// written.
void JobReader::check_result_size() {
  if (limits_.max_result_bytes <= 0 || errors_.size() > 0) return;
  double nodes = 0;
  for (const auto& in : inputs_) nodes += in.body.mesh.num_nodes();
  const bool all = problem_.output.steps == StepOutput::all;
  double kept = 1;
  std::string why, pointer = "/bodies";
  if (problem_.adaptivity.enabled) {
    // Its meshes are not known before it runs: it refines within what the limit leaves (max_kept_nodes); the
    // first mesh must fit.
    const double kept_steps = all ? problem_.adaptivity.max_steps + 1.0 : 1.0;
    problem_.adaptivity.max_kept_nodes =
        std::max(1.0, io::kept_nodes_within(limits_.max_result_bytes, static_cast<double>(inputs_.size()),
                                            static_cast<double>(problem_.contacts.size()), kept_steps));
    why = read::format_number(nodes) + " nodes in the first mesh of an adaptive run";
  } else {
    why = read::format_number(nodes) + " nodes";
    if (all && problem_.loading.factors.size() > 1) {
      kept = static_cast<double>(problem_.loading.factors.size());
      why += " in each of " + read::format_number(kept) + " load steps kept (output.steps \"all\")";
      pointer = "/loading";
    }
  }
  const double bytes = io::estimated_result_bytes(nodes, static_cast<double>(inputs_.size()),
                                                  static_cast<double>(problem_.contacts.size()), kept);
  if (bytes <= limits_.max_result_bytes) return;
  errors_.add(pointer, "the result would take about " + size(bytes) + " (" + why + "), more than the " +
                           size(limits_.max_result_bytes) + " accepted" +
                           (limits_.result_bytes_hint.empty() ? "" : " (" + limits_.result_bytes_hint + ")") +
                           (all && kept > 1 ? ": keep only the last step (\"output\": {\"steps\": \"last\"}), or "
                                              "take fewer steps or coarser meshes"
                                            : ": take coarser meshes"));
}

// The interface problem's memory (estimate_interface_memory, contact/problem.hpp), from the contact edges' nodes,
// before anything is factorised. Only interface_newton builds these blocks (neumann, robin and monolithic do not).
// An adaptive run is estimated on its first mesh here; its refinement stops where the next meshes would pass the
// limit (AdaptivitySettings::max_interface_bytes, set here).
void JobReader::check_interface_memory() {
  if (limits_.max_interface_bytes <= 0 || errors_.size() > 0 || problem_.contacts.empty() ||
      problem_.solver.method != Method::interface_newton)
    return;
  problem_.adaptivity.max_interface_bytes = limits_.max_interface_bytes;
  const InterfaceMemoryEstimate estimate =
      estimate_interface_memory(problem_.contacts, inputs_.size(), [&](int body, const std::string& edge) {
        return static_cast<double>(inputs_[static_cast<size_t>(body)].body.mesh.edge_set_nodes(edge).size());
      });
  const double bytes = estimate.bytes, largest = estimate.largest;
  const size_t top = estimate.body;
  if (bytes <= limits_.max_interface_bytes) return;
  errors_.add("/contacts",
              "the contact interface would take about " + size(bytes) +
                  " of memory (method interface_newton holds dense blocks over each body's contact unknowns: the "
                  "most, " +
                  size(largest) + ", for body '" + inputs_[top].body.name + "' with " +
                  read::format_number(estimate.contact_nodes) + " contact nodes), more than the " +
                  size(limits_.max_interface_bytes) + " accepted" +
                  (limits_.interface_bytes_hint.empty() ? "" : " (" + limits_.interface_bytes_hint + ")") +
                  "; a limit of " + size(bytes * 1.01) +
                  " would admit it. Mesh the contact edges coarser, cut a long body into several bodies, or "
                  "choose method \"monolithic\" (one sparse factorisation of all bodies, no dense blocks)");
}

ParseResult JobReader::finish() {
  ParseResult result;
  if (errors_.size() == 0) {
    for (auto& in : inputs_) problem_.bodies.push_back(std::move(in.body));
    check_initial_gaps();
  }
  result.errors = errors_.take();
  if (result.errors.empty()) {
    result.warnings = problem_.warnings;
    problem_.submitted = job_;
    problem_.normalized = std::move(normalized_);
    result.problem = std::move(problem_);
  }
  return result;
}

// Overlaps and pairs open everywhere, against each pair's fit (check/initial_gaps.hpp): warnings, in the problem and
// the normalized copy; errors for a strict job. Once every mesh is built and nothing else is wrong (the pairs are
// discretised as the solve will).
void JobReader::check_initial_gaps() {
  const auto gaps = check::measure_initial_gaps(problem_, [this] { return out_of_time("measuring the pairs' gaps"); });
  if (timed_out_) return;
  problem_.warnings = check::initial_gap_warnings(problem_, gaps);
  json& listed = normalized_["warnings"];
  listed = json::array();
  for (const auto& w : problem_.warnings) {
    listed.push_back({{"pointer", w.pointer}, {"message", w.message}});
    if (problem_.strict) errors_.add(w.pointer, w.message + " (a strict job takes every warning as an error)");
  }
}

// "strict" (the command line's --strict too, Limits::strict): warnings are errors. "warnings" is what the reader writes
// into the normalized copy; given back (a normalized job submitted again) it is read as nothing and written anew.
void JobReader::read_strict(const Fields& top) {
  problem_.strict = limits_.strict;
  if (const json* v = top.find("strict"))
    if (auto b = read::boolean(*v, top.at("strict"), "strict", errors_)) problem_.strict = problem_.strict || *b;
  set_default(normalized_, "strict", problem_.strict);
}

// The job format's default name (a Problem built in code has none).
constexpr const char* kDefaultJobName = "job";

void JobReader::read_header(const Fields& top) {
  if (const json* v = top.find("name")) {
    if (auto s = read::string(*v, top.at("name"), "name", errors_)) {
      if (auto problem = read::control_character_problem(*s, "name"))
        errors_.add(top.at("name"), *problem);
      else if (s->size() > limits_.max_job_name_length)
        errors_.add(top.at("name"), "name '" + read::shown(*s) + "' is too long: at most " +
                                        std::to_string(limits_.max_job_name_length) + " characters");
      else
        problem_.name = *s;
    }
  } else {
    problem_.name = kDefaultJobName;
  }
  set_default(normalized_, "name", kDefaultJobName);
  if (const json* v = top.find("version")) {
    auto n = read::integer(*v, top.at("version"), "version", errors_);
    if (n && *n != 1)
      errors_.add(top.at("version"),
                  "version " + std::to_string(*n) + " is not supported: this solver reads job format version 1");
  }
  set_default(normalized_, "version", 1);
}

void JobReader::read_model(const Fields& top) {
  json& out = sub_object(normalized_, "model");
  if (const json* v = top.find("model")) {
    Fields f(*v, top.at("model"), "model", {"plane", "thickness", "gravity"}, errors_);
    if (const json* p = f.find("plane")) read_name(*p, f.at("plane"), "plane", problem_.model.plane, errors_);
    if (const json* t = f.find("thickness")) {
      if (auto x = positive(*t, f.at("thickness"), "thickness", errors_)) problem_.model.thickness = *x;
    }
    if (const json* g = f.find("gravity"))
      if (auto x = read::pair(*g, f.at("gravity"), "gravity", errors_)) problem_.model.gravity = *x;
  }
  const Model d;  // contact/problem.hpp's defaults
  set_default(out, "plane", name_of(d.plane));
  set_default(out, "thickness", d.thickness);
  set_default(out, "gravity", json::array({d.gravity.x(), d.gravity.y()}));
}

// The normalized counterpart of a sub-object, created as {} if absent. Where the submitted value has the
// wrong type the job is already in error, and a throw-away value stands in so that reading can go on.
json& JobReader::sub_object(json& parent, const std::string& key) {
  if (!parent.is_object()) return discard();
  if (!parent.contains(key)) parent[key] = json::object();
  return parent[key];
}

json& JobReader::element(json& array, size_t index) {
  if (!array.is_array() || index >= array.size()) return discard();
  return array[index];
}

json& JobReader::discard() {
  discarded_ = json::object();
  return discarded_;
}

}  // namespace detail

namespace {

using detail::JobReader;
using nlohmann::json;
using read::child;
using read::Errors;

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
            errors_.add(pending_pointer(), "duplicate key '" + read::shown(f.key) +
                                               "' in one object (a JSON reader keeps only one of them)");
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
