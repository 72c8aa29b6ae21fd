// The job's contact pairs: their "body.edge" references resolved to the bodies read (phase 5), and their gaps.
#include "job_reader.hpp"
#include "names.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <optional>
#include <string>
#include <utility>

namespace contact::job::detail {

bool JobReader::bodies_all_named() const {
  return std::all_of(inputs_.begin(), inputs_.end(), [](const BodyInput& in) { return in.has_name; });
}

// "body.edge" -> indices; reports what is wrong at `pointer`. A body that is not found is reported only when
// every body's name was read: a job whose bodies were refused whole (over the limit) or whose body names are in
// error has that error already, and every pair naming those bodies would only repeat it.
std::optional<JobReader::EdgeRef> JobReader::resolve(const json& value, const std::string& pointer,
                                                     const std::string& what) {
  auto s = read::string(value, pointer, what, errors_);
  if (!s) return std::nullopt;
  const size_t dot = s->find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == s->size() || s->find('.', dot + 1) != std::string::npos) {
    errors_.add(pointer, what + " must be \"body.edge\" (e.g. \"upper.bottom\"), got \"" + read::shown(*s) + "\"");
    return std::nullopt;
  }
  const std::string body = s->substr(0, dot), edge = s->substr(dot + 1);
  if (!body_index_made_) {
    for (size_t b = 0; b < inputs_.size(); ++b)
      if (inputs_[b].has_name) body_index_.emplace(inputs_[b].body.name, b);
    body_index_made_ = true;
  }
  if (const auto found = body_index_.find(body); found != body_index_.end()) {
    const size_t b = found->second;
    const MeshInput& m = inputs_[b].mesh;
    if (m.edges_known && !has_edge(m, edge)) {
      errors_.add(pointer, gmsh_elsewhere(m, edge).value_or("body '" + body + "' has no edge '" + read::shown(edge) +
                                                            "'; its edges are " + join_names(m.edge_names)));
      return std::nullopt;
    }
    return EdgeRef{static_cast<int>(b), edge};
  }
  std::vector<std::string> names;
  for (const auto& input : inputs_)
    if (input.has_name) names.push_back(input.body.name);
  if (bodies_listed_ && bodies_all_named())
    errors_.add(pointer, "there is no body named '" + read::shown(body) + "'; the bodies are " + join_names(names));
  return std::nullopt;
}

void JobReader::read_contacts(const Fields& top) {
  json& out_list = sub_object(normalized_, "contacts");
  const json* list = top.find("contacts");
  if (!list) {
    out_list = json::array();
    return;
  }
  if (!list->is_array()) {
    errors_.add("/contacts", "contacts must be an array, got " + read::type_name(*list));
    contacts_complete_ = false;
    return;
  }
  if (list->size() > static_cast<size_t>(limits_.max_contacts)) {  // refused before any pair is read
    contacts_complete_ = false;
    errors_.add("/contacts", "the job has " + std::to_string(list->size()) + " contact pairs; at most " +
                                 std::to_string(limits_.max_contacts) + " are accepted");
    return;
  }
  std::map<std::string, std::string> pointer_of_name;
  std::map<std::pair<std::string, std::string>, std::string> pointer_of_pair;
  for (size_t k = 0; k < list->size(); ++k) {
    if (k % 64 == 63 && out_of_time("reading the contact pairs")) return;
    const std::string cp = child("/contacts", k);
    json& out = element(out_list, k);
    Fields f((*list)[k], cp, "a contact", {"name", "slave", "master", "gap", "friction", "fit"}, errors_);
    if (!f.ok()) {
      contacts_complete_ = false;
      continue;
    }
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
    read_friction(f, pair.friction);
    if (const json* v = f.find("fit")) read_name(*v, f.at("fit"), "fit", pair.fit, errors_);
    set_default(out, "fit", name_of(ContactPair{}.fit));
    if (errors_.size() == before) {
      problem_.contacts.push_back(pair);
      friction_pointers_.push_back(pair.friction.active() ? f.at("friction") : std::string());
      contact_pointers_.push_back(cp);
    } else {
      contacts_complete_ = false;
    }
  }
}

namespace {

// An edge's sides as a polyline of points (a closed loop's first node again at its end).
std::vector<Eigen::Vector2d> edge_polyline(const mesh::Mesh& mesh, const std::string& edge) {
  std::vector<Eigen::Vector2d> points;
  const std::vector<int> nodes = mesh.edge_set_nodes(edge);
  for (const int n : nodes) points.push_back(mesh.nodes[static_cast<size_t>(n)]);
  if (mesh.edge_set_closed(edge) && !points.empty()) points.push_back(points.front());
  return points;
}

std::string point_text(const Eigen::Vector2d& p) {
  std::ostringstream os;
  os.precision(6);
  os << "(" << p.x() << ", " << p.y() << ")";
  return os.str();
}

enum class Facing { yes, no_overlap, normals_agree, unknown };

// Whether a side of the slave edge faces a side of the master edge as the mortar discretisation pairs them
// (solver/mortar/segments.hpp): their outward normals oppose, and the master side's projection on the slave side's
// line overlaps the slave side. A pair with no such sides could never carry a force. The search stops at the first
// facing sides (tried from the master's end that meets the slave's start: the two run in opposite directions), and
// after `budget` side pairs without one it says unknown (the solve reports such a pair when it discretises it).
Facing edges_face(const std::vector<Eigen::Vector2d>& slave, const std::vector<Eigen::Vector2d>& master,
                  long long& budget) {
  bool overlap_seen = false;
  for (size_t k = 0; k + 1 < slave.size(); ++k) {
    const Eigen::Vector2d a = slave[k], e = slave[k + 1] - a;
    const double L2 = e.squaredNorm();
    if (!(L2 > 0)) continue;
    const Eigen::Vector2d n(e.y(), -e.x());
    for (size_t r = master.size(); r-- > 1;) {
      if (--budget < 0) return Facing::unknown;
      const Eigen::Vector2d &c = master[r - 1], &d = master[r];
      const Eigen::Vector2d f = d - c;
      const double xc = (c - a).dot(e) / L2, xd = (d - a).dot(e) / L2;
      if (!(std::min(std::max(xc, xd), 1.0) - std::max(std::min(xc, xd), 0.0) > 1e-9)) continue;
      overlap_seen = true;
      const Eigen::Vector2d m(f.y(), -f.x());  // the master side's outward normal (unnormalised)
      if (m.dot(n) < -1e-12 * std::sqrt(L2) * f.norm()) return Facing::yes;
    }
  }
  return overlap_seen ? Facing::normals_agree : Facing::no_overlap;
}

}  // namespace

// A pair whose edges never face each other (a mistyped edge: "b0.top" for "b0.right", a slave and master on the
// same side of a joint) would be solved as a pair that carries nothing, or fail in the solve with a message that
// blames the loads. The check costs at most kFacingBudget side pairs over the job (a typical pair finds facing
// sides at once); past it the pairs left are checked by the solve.
void JobReader::check_pairs_face() {
  // Only on meshes read without an error: a mesh given with errors is built in part, and its edges may not be
  // chains (an edge's nodes would then not be an ordered list to walk).
  if (errors_.size() > 0) return;
  constexpr long long kFacingBudget = 20'000'000;
  long long budget = kFacingBudget;
  for (size_t k = 0; k < problem_.contacts.size() && budget > 0; ++k) {
    if (k % 64 == 63 && out_of_time("checking that the pairs' edges face each other")) return;
    const ContactPair& c = problem_.contacts[k];
    const Body& slave_body = inputs_[static_cast<size_t>(c.slave_body)].body;
    const Body& master_body = inputs_[static_cast<size_t>(c.master_body)].body;
    const auto slave = edge_polyline(slave_body.mesh, c.slave_edge);
    const auto master = edge_polyline(master_body.mesh, c.master_edge);
    if (slave.size() < 2 || master.size() < 2) continue;  // a mesh not built: its error is given
    const Facing facing = edges_face(slave, master, budget);
    if (facing == Facing::yes || facing == Facing::unknown) continue;
    const std::string s = slave_body.name + "." + c.slave_edge, m = master_body.name + "." + c.master_edge;
    const std::string where = "slave " + s + " runs from " + point_text(slave.front()) + " to " +
                              point_text(slave.back()) + ", master " + m + " from " + point_text(master.front()) +
                              " to " + point_text(master.back());
    errors_.add(contact_pointers_[k],
                "the edges of pair '" + c.name + "' never face each other (" + where + "): " +
                    (facing == Facing::no_overlap
                         ? "no side of the master lies opposite a side of the slave, along the slave's normal"
                         : "where they lie opposite each other their outward normals point the same way, so the "
                           "bodies are on the same side of them") +
                    "; such a pair could never carry a force. Name the edges that meet (a block's are bottom, "
                    "right, top and left)");
  }
}

void JobReader::read_gap(const Fields& contact, GapSpec& gap, json& out) {
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
      set_default(sub_object(out, "parabola"), "x0", GapSpec{}.parabola_x0);
    }
  }
  const GapSpec d;  // contact/problem.hpp's defaults
  set_default(out, "geometric", d.geometric);
  set_default(out, "constant", d.constant);
}

}  // namespace contact::job::detail
