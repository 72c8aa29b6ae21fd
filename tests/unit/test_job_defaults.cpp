// One source of the job's defaults and one wording of its rules (issue 27, item 3). The reader takes its defaults
// from the settings structs of contact/problem.hpp; api/job.schema.json's "default"s are held to the reader's
// normalized copy here, both ways. The rule on method and enforcement that both the reader and solve() check is
// one function (contact::settings_conflict).
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "contact/job.hpp"
#include "contact/solve.hpp"

using contact::job::parse;
using contact::job::ParseResult;
using nlohmann::json;

namespace {

std::string listing(const ParseResult& r) { return contact::job::format_errors(r.errors); }

json read_schema() {
  std::ifstream in(std::string(CONTACT_SOURCE_DIR) + "/api/job.schema.json");
  return json::parse(in, nullptr, /*allow_exceptions=*/false);
}

std::string child(const std::string& pointer, const std::string& token) { return pointer + "/" + token; }

// A node of the schema with its JSON pointer in the schema document (which names a default in the messages and
// in the check that the jobs reach every default).
struct SchemaNode {
  const json* node = nullptr;
  std::string at;
};

// Walks a job's normalized copy (the submitted job with every default the reader writes) and the schema together,
// from the root. At each object of the copy it takes the object's schema ("$ref" followed; of a "oneOf", the
// branch whose "required" keys the object has and whose "properties" hold all of its keys) and checks both ways:
//  * schema -> reader (check_left_out): every property with a "default" that the job left out is in the copy
//    with that value. An object's default names some of its members, which are compared; the others have
//    defaults of their own, compared one level down.
//  * reader -> schema (written): every member of the copy that the job did not give, so the reader
//    wrote it, has a schema "default": its own, or a member of the default of the object around it when the
//    reader wrote that object whole ({"steps": 1} of "loading"). An object the reader wrote without a default of
//    its own ("interface") is checked member by member. The defaults that follow from the rest of the job
//    (kJobDependent) have no schema default: the schema's descriptions say how they follow.
// Arrays the job gave are walked element by element ("items"); one the reader wrote is a default as a whole.
// Every schema default compared is recorded, for the check that the jobs reach them all.
class DefaultsWalk {
 public:
  explicit DefaultsWalk(const json& schema) : schema_(schema) {}

  // `job` names the job in the failures.
  void run(const std::string& job, const json& submitted, const json& normalized) {
    job_ = job;
    visit("", {&schema_, ""}, normalized, &submitted, nullptr);
  }

  std::set<std::string> compared;     // schema pointers of the defaults compared
  std::vector<std::string> failures;  // one line each: where, what the schema says, what the reader wrote

 private:
  // Where in a job (an array index as "*") the default follows from the rest of the job.
  const std::vector<std::vector<std::string>> kJobDependent = {
      {"output", "steps"},        // "last" for an adaptive job, else "all"
      {"adaptivity", "bodies"},   // every named body
      {"contacts", "*", "name"},  // "slave-master"
  };

  const json& schema_;
  std::string job_;

  SchemaNode follow(const SchemaNode& s) const {
    const std::string ref = (*s.node)["$ref"].get<std::string>().substr(1);  // "#/$defs/..." -> "/$defs/..."
    return {&schema_.at(json::json_pointer(ref)), ref};
  }

  SchemaNode deref(SchemaNode s) const {
    while (s.node->is_object() && s.node->contains("$ref")) s = follow(s);
    return s;
  }

  // The default on the node or on what it refers to ({"$ref": ..., "default": ...} has its own).
  std::optional<SchemaNode> default_of(SchemaNode s) const {
    while (s.node->is_object()) {
      if (s.node->contains("default")) return SchemaNode{&(*s.node)["default"], child(s.at, "default")};
      if (!s.node->contains("$ref")) break;
      s = follow(s);
    }
    return std::nullopt;
  }

  // A "oneOf" branch that describes the object's members; branches that only say which key is required (a
  // mesh's gmsh source, friction, loading) leave the properties to the node holding them.
  static bool branch_fits(const json& branch, const json& object) {
    if (!branch.contains("properties")) return false;
    for (const auto& key : branch.value("required", json::array()))
      if (!object.contains(key.get<std::string>())) return false;
    for (const auto& item : object.items())
      if (!branch["properties"].contains(item.key())) return false;
    return true;
  }

  SchemaNode resolved(const SchemaNode& s, const json& value) const {
    const SchemaNode r = deref(s);
    if (!r.node->contains("oneOf") || !value.is_object()) return r;
    const json& branches = (*r.node)["oneOf"];
    for (size_t i = 0; i < branches.size(); ++i) {
      const SchemaNode b = deref({&branches[i], child(r.at, "oneOf/" + std::to_string(i))});
      if (branch_fits(*b.node, value)) return b;
    }
    return r;
  }

  static std::optional<SchemaNode> member(const SchemaNode& r, const std::string& key) {
    if (r.node->contains("properties") && (*r.node)["properties"].contains(key))
      return SchemaNode{&(*r.node)["properties"][key], child(r.at, "properties/" + key)};
    if (r.node->contains("additionalProperties") && (*r.node)["additionalProperties"].is_object())
      return SchemaNode{&(*r.node)["additionalProperties"], child(r.at, "additionalProperties")};
    return std::nullopt;  // not a member the schema knows: nothing below it has a default
  }

  // The reader's value is the default: equal (1 == 1.0 for nlohmann), or for an object default, equal in every
  // member the default names.
  static bool agrees(const json& value, const json& d) {
    if (!d.is_object() || !value.is_object()) return value == d;
    for (const auto& item : d.items())
      if (!value.contains(item.key()) || !agrees(value[item.key()], item.value())) return false;
    return true;
  }

  bool job_dependent(const std::vector<std::string>& path) const {
    for (const auto& pattern : kJobDependent) {
      bool same = pattern.size() == path.size();
      for (size_t i = 0; same && i < path.size(); ++i)
        same = pattern[i] == path[i] ||
               (pattern[i] == "*" && !path[i].empty() && path[i].find_first_not_of("0123456789") == std::string::npos);
      if (same) return true;
    }
    return false;
  }

  // `given`: the submitted value here (nullptr: the reader wrote it); `around`: the default that covers this
  // object when the reader wrote it whole.
  void visit(const std::string& at, const SchemaNode& s, const json& value, const json* given, const json* around) {
    const SchemaNode r = resolved(s, value);
    if (value.is_array() && given && r.node->contains("items") && (*r.node)["items"].is_object()) {
      const SchemaNode items{&(*r.node)["items"], child(r.at, "items")};
      for (size_t i = 0; i < value.size() && i < given->size(); ++i)
        visit(child(at, std::to_string(i)), items, value[i], &(*given)[i], nullptr);
    }
    if (!value.is_object()) return;
    check_left_out(at, r, value, given);
    for (const auto& item : value.items()) {
      const std::string key = item.key(), where = child(at, key);
      const json* g = given && given->is_object() && given->contains(key) ? &(*given)[key] : nullptr;
      const auto m = member(r, key);
      if (g) {
        if (m) visit(where, *m, item.value(), g, nullptr);
        continue;
      }
      const Written w = written(where, m, item.value(), around);
      if (w.go_in && m) visit(where, *m, item.value(), nullptr, w.around);
    }
  }

  // Schema -> reader: the defaults of the members the job left out.
  void check_left_out(const std::string& at, const SchemaNode& r, const json& value, const json* given) {
    if (!r.node->contains("properties")) return;
    for (const auto& item : (*r.node)["properties"].items()) {
      const std::string key = item.key();
      if (given && given->is_object() && given->contains(key)) continue;  // the job's value, not a default
      const auto d = default_of({&item.value(), child(r.at, "properties/" + key)});
      if (!d) continue;
      compared.insert(d->at);
      if (!value.contains(key))
        failures.push_back(job_ + " " + child(at, key) + ": the schema's default " + d->node->dump() + " (" + d->at +
                           ") is not in the normalized copy");
      else if (!agrees(value[key], *d->node))
        failures.push_back(job_ + " " + child(at, key) + ": the schema's default is " + d->node->dump() + " (" + d->at +
                           ") but the reader writes " + value[key].dump());
    }
  }

  // Reader -> schema: a member the reader wrote, and how the walk goes on into it: an object is walked with the
  // default that covers it (its own, or the member of `around`), or member by member if it has none. A member
  // that is neither a default nor an object with members is reported.
  struct Written {
    bool go_in = false;
    const json* around = nullptr;
  };
  Written written(const std::string& where, const std::optional<SchemaNode>& m, const json& value, const json* around) {
    const std::string key = where.substr(where.rfind('/') + 1);
    if (job_dependent(tokens(where))) return {};
    const json* cover = nullptr;
    if (const auto d = m ? default_of(*m) : std::nullopt) {
      cover = d->node;  // compared by check_left_out, but for a name's default under "additionalProperties"
      const std::string extra = "/additionalProperties";
      if (m->at.size() > extra.size() && m->at.compare(m->at.size() - extra.size(), extra.size(), extra) == 0) {
        compared.insert(d->at);  // (an explicit mesh's curves: no property check_left_out sees)
        if (!agrees(value, *d->node))
          failures.push_back(job_ + " " + where + ": the schema's default is " + d->node->dump() + " (" + d->at +
                             ") but the reader writes " + value.dump());
      }
    } else if (around && around->contains(key))
      cover = &(*around)[key];  // compared as part of that default, one level up
    if (cover) return {value.is_object(), cover->is_object() ? cover : nullptr};
    if (value.is_object() && !value.empty()) return {true, nullptr};
    failures.push_back(job_ + " " + where + ": the reader writes " + value.dump() +
                       " but the schema has no default for it" + (m ? " (" + m->at + ")" : " (nor the property)"));
    return {};
  }

  static std::vector<std::string> tokens(const std::string& pointer) {
    std::vector<std::string> out;
    for (size_t start = 1; start <= pointer.size();) {
      const size_t end = std::min(pointer.find('/', start), pointer.size());
      out.push_back(pointer.substr(start, end - start));
      start = end + 1;
    }
    return out;
  }
};

// Every "default" in the schema document, by its pointer.
void collect_defaults(const json& node, const std::string& at, std::set<std::string>& out) {
  if (node.is_object()) {
    for (const auto& item : node.items()) {
      const std::string where = child(at, item.key());
      if (item.key() == "default")
        out.insert(where);
      else
        collect_defaults(item.value(), where, out);
    }
  } else if (node.is_array()) {
    for (size_t i = 0; i < node.size(); ++i) collect_defaults(node[i], child(at, std::to_string(i)), out);
  }
}

// The jobs the walk reads; together they leave out every field that has a default.
// One body, an explicit mesh without edges held at two named vertices, no contacts, no solver, and an empty
// "adaptivity": the top level's, the solver's and adaptivity's defaults.
json lone_body_job() {
  return json::parse(R"({
    "bodies": [
      {"name": "plate", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"nodes": [[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]], "quads": [[0, 1, 4, 3], [1, 2, 5, 4]],
                "vertices": {"a": 0, "b": 2, "c": 5}},
       "boundary": [{"vertex": "a", "displacement": {"x": 0, "y": 0}}, {"vertex": "b", "displacement": {"y": 0}},
                    {"vertex": "c", "force": [0, -1]}]}
    ],
    "adaptivity": {}
  })");
}

// A box held by its contacts alone (no "boundary") in the corner of a wall and a floor, pushed into the corner by a
// live load of an empty "collapse" (its defaults): the pairs' defaults, one with a gap parabola; the sections given
// empty, where the reader fills in the members (the solver's penalty, augmented-Lagrangian and interface settings too).
// Not "robin": {}: the reader writes psi only where the whole "robin" is left out, so a given empty "robin" stays {} in
// the copy (psi "active_set" is meant all the same).
json corner_job() {
  return json::parse(R"({
    "name": "corner",
    "model": {},
    "bodies": [
      {"name": "box", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"nodes": [[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]], "quads": [[0, 1, 4, 3], [1, 2, 5, 4]],
                "edges": {"base": [[0, 1], [1, 2]], "wall": [[3, 0]]}},
       "body_force": {"value": [-1, 0], "live": true}},
      {"name": "floor", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, -1], [2, -1], [2, 0], [0, 0]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "bottom", "displacement": {"x": 0, "y": 0}}]},
      {"name": "wall", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[-1, 0], [0, 0], [0, 1], [-1, 1]], "nx": 1, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0.001, "y": 0}}]}
    ],
    "contacts": [{"slave": "box.base", "master": "floor.top", "gap": {"parabola": {"r0": 0}}},
                 {"slave": "box.wall", "master": "wall.right"}],
    "solver": {"penalty": {}, "augmented_lagrangian": {}, "interface": {}},
    "parallel": {},
    "output": {},
    "collapse": {}
  })");
}

// Two blocks pressed together, each held against rigid motion: a job every method can run.
json pressed_blocks_job() {
  return json::parse(R"({
    "bodies": [
      {"name": "upper", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, 0], [2, 0], [2, 1], [0, 1]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0}}, {"edge": "top", "displacement": {"y": -0.001}}]},
      {"name": "lower", "material": {"E": 2.1e5, "nu": 0.3},
       "mesh": {"block": {"corners": [[0, -1], [2, -1], [2, 0], [0, 0]], "nx": 2, "ny": 1}},
       "boundary": [{"edge": "left", "displacement": {"x": 0}}, {"edge": "bottom", "displacement": {"y": 0}}]}
    ],
    "contacts": [{"slave": "upper.bottom", "master": "lower.top"}]
  })");
}

}  // namespace

TEST(JobSchemaDefaults, EverySchemaDefaultIsTheReadersAndEveryDefaultTheReaderWritesIsInTheSchema) {
  const json schema = read_schema();
  ASSERT_TRUE(schema.is_object()) << "api/job.schema.json not read";
  DefaultsWalk walk(schema);
  for (const auto& [name, job] : {std::pair{"lone_body_job", lone_body_job()}, std::pair{"corner_job", corner_job()}}) {
    const ParseResult r = parse(job);
    ASSERT_TRUE(r.ok()) << name << ": " << listing(r);
    walk.run(name, job, r.problem->normalized);
  }
  std::string failures;
  for (const auto& f : walk.failures) failures += f + "\n";
  EXPECT_TRUE(walk.failures.empty()) << failures;
  // The jobs reach every default of the schema: one added where they do not go must come with a job that does.
  std::set<std::string> all;
  collect_defaults(schema, "", all);
  std::string missed;
  for (const auto& d : all)
    if (!walk.compared.count(d)) missed += d + "\n";
  EXPECT_TRUE(missed.empty()) << "schema defaults no job of this test leaves out:\n" << missed;
  EXPECT_GE(walk.compared.size(), 40u);
}

// Exact enforcement with a method that iterates on the penalty problem: one rule (contact::settings_conflict),
// reported by the reader at the enforcement's pointer and by solve() for a Problem built in code, in the same words.
TEST(SettingsConflict, ExactEnforcementOfAPenaltyIterationIsRefusedInOneWordingByTheReaderAndBySolve) {
  for (const char* method : {"neumann", "robin"}) {
    contact::SolverSettings settings;
    settings.method = *contact::method_named(method);
    settings.enforcement = contact::Enforcement::exact;
    const std::string rule = contact::settings_conflict(settings);
    ASSERT_NE(rule.find("iterates on the penalty problem"), std::string::npos) << rule;

    json job = pressed_blocks_job();
    job["solver"] = {{"method", method}, {"enforcement", "exact"}};
    const ParseResult refused = parse(job);
    ASSERT_EQ(refused.errors.size(), 1u) << listing(refused);
    EXPECT_EQ(refused.errors[0].pointer, "/solver/enforcement");
    EXPECT_EQ(refused.errors[0].message, rule);

    job["solver"] = {{"method", method}};  // penalty by default: valid; then made exact in code
    ParseResult read = parse(job);
    ASSERT_TRUE(read.ok()) << listing(read);
    contact::Problem problem = std::move(*read.problem);
    problem.solver.enforcement = contact::Enforcement::exact;
    contact::Observer observer;
    contact::CancelToken cancel;
    const contact::Result result = contact::solve(problem, observer, cancel);
    EXPECT_EQ(result.stop_reason, contact::StopReason::error);
    EXPECT_NE(result.message.find(rule), std::string::npos) << result.message;
  }
  // Every other combination can run.
  for (const auto method : {contact::Method::neumann, contact::Method::robin, contact::Method::monolithic,
                            contact::Method::interface_newton})
    for (const auto enforcement :
         {contact::Enforcement::exact, contact::Enforcement::penalty, contact::Enforcement::augmented_lagrangian}) {
      contact::SolverSettings settings;
      settings.method = method;
      settings.enforcement = enforcement;
      const bool conflict = contact::iterates_on_penalty(method) && enforcement == contact::Enforcement::exact;
      EXPECT_EQ(contact::settings_conflict(settings).empty(), !conflict)
          << contact::to_string(method) << " " << contact::to_string(enforcement);
    }
}
