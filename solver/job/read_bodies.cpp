// The job's bodies: names, materials and boundary conditions (phase 1), then the limit on degrees of freedom
// (phase 2), the meshes (phase 3, read_meshes.cpp) and the checks that need them (phase 4): restraint against
// rigid motion, loads that reach the body, floating bodies held by their contacts.
#include "job_reader.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "../mesh/rigid_modes.hpp"

namespace contact::job::detail {

void JobReader::read_bodies(const Fields& top) {
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
  bodies_listed_ = true;
  json& out_list = normalized_["bodies"];
  std::map<std::string, std::string> first_pointer_of_name;
  for (size_t i = 0; i < list->size(); ++i) {
    if (i % 64 == 63 && out_of_time("reading the bodies")) return;
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
  std::vector<const BodyInput*> sized;
  for (const auto& in : inputs_) {
    if (in.mesh.dofs < 0) continue;
    total += in.mesh.dofs;
    sized.push_back(&in);
  }
  if (total > static_cast<double>(limits_.max_dofs)) {
    // The largest bodies first, at most eight of them named (a job of 8,192 bodies gets one line, not 8,192).
    constexpr size_t kNamed = 8;
    std::stable_sort(sized.begin(), sized.end(),
                     [](const BodyInput* a, const BodyInput* b) { return a->mesh.dofs > b->mesh.dofs; });
    std::vector<std::string> parts;
    for (size_t k = 0; k < std::min(kNamed, sized.size()); ++k)
      parts.push_back((sized[k]->has_name ? "'" + sized[k]->body.name + "'" : sized[k]->pointer) + " " +
                      format_number(sized[k]->mesh.dofs));
    if (sized.size() > kNamed)
      parts.push_back(std::to_string(sized.size() - kNamed) + " more bod" + (sized.size() - kNamed == 1 ? "y" : "ies"));
    errors_.add("/bodies", "the meshes would have " + format_number(total) + " degrees of freedom (" +
                               join_names(parts) + "), more than the limit of " +
                               format_number(static_cast<double>(limits_.max_dofs)));
    return;
  }

  // Phase 3: meshes; phase 4: rigid motion.
  for (size_t i = 0; i < inputs_.size(); ++i) {
    BodyInput& in = inputs_[i];
    if (i % 64 == 63 && out_of_time("building the bodies' meshes")) return;
    if (!in.mesh.valid) continue;
    build_mesh(in);
    if (errors_.count_under(in.pointer) == 0) {
      check_restrained(in);
      check_loads_reach_the_body(in);
    }
  }
}

void JobReader::read_body(const json& value, BodyInput& in, json& out) {
  Fields f(value, in.pointer, "a body", {"name", "material", "mesh", "boundary", "body_force"}, errors_);
  if (!f.ok()) return;
  if (const json* n = f.require("name", "a name of letters, digits, '_' and '-', unique among the bodies"))
    if (auto s = identifier(*n, f.at("name"), "body name", limits_.max_name_length, errors_)) {
      in.body.name = *s;
      in.has_name = true;
    }
  if (const json* m = f.require("material", "an object {\"E\": Young's modulus, \"nu\": Poisson's ratio}")) {
    read_material(*m, f.at("material"), in.body.material);
    set_default(sub_object(out, "material"), "density", Material{}.density);
  }
  if (const json* m = f.require("mesh",
                                "one of {\"block\": {...}}, {\"nodes\": ..., \"quads\": ..., \"edges\": ...} "
                                "or {\"gmsh\": {...}}"))
    read_mesh(*m, f.at("mesh"), in.mesh, sub_object(out, "mesh"));
  if (const json* b = f.find("boundary")) read_boundary(*b, f.at("boundary"), in);
  set_default(out, "boundary", json::array());
  if (const json* b = f.find("body_force")) read_body_force(*b, f.at("body_force"), in);
  const Eigen::Vector2d none = Body{}.body_force;  // contact/problem.hpp's default
  set_default(out, "body_force", json::array({none.x(), none.y()}));
}

// [x, y] (force per volume, following the loading), or {"value": [x, y], "history": [...]}: its own factor per
// load step, as a condition's history.
void JobReader::read_body_force(const json& value, const std::string& pointer, BodyInput& in) {
  if (!value.is_object()) {
    if (auto v = read::pair(value, pointer, "body_force", errors_)) in.body.body_force = *v;
    return;
  }
  Fields f(value, pointer, "body_force", {"value", "history", "live"}, errors_);
  if (!f.ok()) return;
  if (const json* v = f.require("value", "the force per volume [x, y]"))
    if (auto x = read::pair(*v, f.at("value"), "value", errors_)) in.body.body_force = *x;
  read_history(f, in.body.body_force_history);
  if (f.has("history")) in.body_force_pointer = pointer;
  in.body.body_force_live = read_live(f);
  if (in.body.body_force_live) in.live_pointers.push_back(f.at("live"));
}

void JobReader::read_material(const json& value, const std::string& pointer, Material& material) {
  Fields f(value, pointer, "material", {"E", "nu", "density"}, errors_);
  if (const json* d = f.find("density"))
    if (auto x = read::number(*d, f.at("density"), "density", errors_)) {
      if (*x >= 0)
        material.density = *x;
      else
        errors_.add(f.at("density"), "density = " + format_number(*x) + " must not be negative (mass per volume)");
    }
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
        errors_.add(f.at("nu"), "nu = " + format_number(*x) +
                                    " is outside (-1, 0.5): Poisson's ratio must be greater than -1 and less than 0.5");
    }
}

void JobReader::read_boundary(const json& value, const std::string& pointer, BodyInput& in) {
  if (!value.is_array()) {
    errors_.add(pointer, "boundary must be an array of conditions, got " + read::type_name(value));
    return;
  }
  std::map<std::string, PlaceUse> first_pointer_of_place;
  for (size_t j = 0; j < value.size(); ++j) read_condition(value[j], child(pointer, j), in, first_pointer_of_place);
}

// One boundary condition: where (an edge or a vertex), what (displacement, load, both on different components,
// free), its load history; kept in the body only if all of it reads without error.
void JobReader::read_condition(const json& value, const std::string& bp, BodyInput& in,
                               std::map<std::string, PlaceUse>& first_pointer_of_place) {
  Fields f(value, bp, "a boundary condition",
           {"edge", "vertex", "displacement", "traction", "force", "free", "history", "live"}, errors_);
  if (!f.ok()) return;
  const size_t before = errors_.size();
  BoundaryCondition bc;
  if (f.has("edge") == f.has("vertex")) {
    errors_.add(bp, "give exactly one of edge (a named edge of the body) and vertex (a named vertex)");
    return;
  }
  const bool at_vertex = f.has("vertex");
  read_condition_place(f, at_vertex, in.mesh, bc, first_pointer_of_place);
  if (!condition_kinds_allowed(f, bp, at_vertex)) return;
  read_condition_values(f, bp, bc);
  check_loads_off_supports(f, bp, bc);
  read_history(f, bc.history);
  bc.live = read_live(f);
  if (errors_.size() == before) {
    in.body.boundary.push_back(bc);
    in.condition_pointers.push_back(bp);
    if (bc.live) in.live_pointers.push_back(f.at("live"));
  }
}

// The condition's edge or vertex: a named one of the body's mesh, and the first condition there.
void JobReader::read_condition_place(const Fields& f, bool at_vertex, const MeshInput& mesh, BoundaryCondition& bc,
                                     std::map<std::string, PlaceUse>& first_pointer_of_place) {
  const std::string bp = f.pointer();
  const std::string place_key = at_vertex ? "vertex" : "edge";
  const std::vector<std::string>& names = at_vertex ? mesh.vertex_names : mesh.edge_names;
  if (const json* e = f.find(place_key))
    if (auto s = read::string(*e, f.at(place_key), place_key, errors_)) {
      (at_vertex ? bc.vertex : bc.edge) = *s;
      const bool known = std::find(names.begin(), names.end(), *s) != names.end();
      if (mesh.edges_known && !known) {
        const auto elsewhere = gmsh_elsewhere(mesh, *s, at_vertex);
        errors_.add(f.at(place_key),
                    elsewhere.value_or("the body has no " + place_key + " '" + read::shown(*s) + "'; " +
                                       (names.empty() ? std::string("it has no named ") + place_key + "s"
                                                      : "its " + std::string(at_vertex ? "vertices" : "edges") +
                                                            " are " + join_names(names))));
      } else {
        // Loads alone may share a place (a precompression and a shear with histories of their own): they add.
        const bool load_only = (f.has("traction") || f.has("force")) && !f.has("displacement") && !f.has("free");
        auto [it, inserted] = first_pointer_of_place.emplace(place_key + ":" + *s, PlaceUse{bp, load_only});
        if (!inserted && !(load_only && it->second.loads_only))
          errors_.add(f.at(place_key), place_key + " '" + *s + "' already has a condition at " + it->second.pointer +
                                           "; a displacement (or \"free\") is the only condition of its " + place_key +
                                           " (it fixes only its given components: a load on the other "
                                           "goes in the same condition); several loads on one " +
                                           place_key + " add");
      }
    }
}

// One kind of condition or a displacement with a load; at a vertex no traction and no "free". False (reported)
// if not.
bool JobReader::condition_kinds_allowed(const Fields& f, const std::string& bp, bool at_vertex) {
  const int loads = int(f.has("traction")) + int(f.has("force"));
  const int kinds = int(f.has("displacement")) + loads + int(f.has("free"));
  if (kinds == 0 || loads > 1 || (f.has("free") && kinds > 1)) {
    errors_.add(bp,
                "give a displacement, a load (traction or force), a displacement with a load on the other "
                "component, or free");
    return false;
  }
  if (at_vertex && (f.has("traction") || f.has("free"))) {
    errors_.add(bp, "a vertex takes a displacement (a point support) or a force (a point load), not " +
                        std::string(f.has("traction") ? "a traction (a force per length)" : "free"));
    return false;
  }
  return true;
}

// The prescribed displacement components, the traction (a vector or a normal pressure), the force, or "free".
void JobReader::read_condition_values(const Fields& f, const std::string& bp, BoundaryCondition& bc) {
  const bool loads = f.has("traction") || f.has("force");
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
}

// A load may not act where the displacement is prescribed: it would go straight into the support.
void JobReader::check_loads_off_supports(const Fields& f, const std::string& bp, const BoundaryCondition& bc) {
  if (f.has("displacement") && bc.normal_pressure)
    errors_.add(bp,
                "a normal pressure cannot be combined with a displacement (part of it would go into the "
                "support); give the traction as a vector [tx, ty] along the free component");
  // A load component along a prescribed displacement component would go straight into the support.
  const Eigen::Vector2d load = bc.kind == BoundaryCondition::Kind::force ? bc.force
                               : bc.kind == BoundaryCondition::Kind::traction && !bc.normal_pressure
                                   ? bc.traction
                                   : Eigen::Vector2d::Zero();
  for (int c = 0; c < 2; ++c)
    if ((c == 0 ? bc.ux : bc.uy) && load[c] != 0.0)
      errors_.add(bp, std::string("the load's ") + (c == 0 ? "x" : "y") + " component acts where the " +
                          (c == 0 ? "x" : "y") + " displacement is prescribed: it would go straight into the support");
}

// Phase 4: the rigid motions a body's displacement conditions leave free. A body that some are free for may
// still be held by its contacts (check_floating_bodies decides, once the contacts and the method are known).
void JobReader::check_restrained(BodyInput& in) {
  const mesh::Mesh& mesh = in.body.mesh;
  std::set<mesh::PrescribedDof> dofs;
  for (const auto& bc : in.body.boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(mesh, bc)) {
      if (bc.ux) dofs.insert({node, 0});
      if (bc.uy) dofs.insert({node, 1});
    }
  }
  in.free_motions = mesh::free_rigid_motions(mesh, std::vector<mesh::PrescribedDof>(dofs.begin(), dofs.end()));
}

// A traction or force whose every node is held in both directions by displacement conditions would go straight
// into the supports and move nothing: almost certainly a mistake in the job, so an error at that condition.
void JobReader::check_loads_reach_the_body(const BodyInput& in) {
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

namespace {

// The directions in which body i is held whatever the loads, at best: its prescribed components, and the normal of
// every node of its contact edges (a frictionless contact pushes only along it); a contact with friction may also
// hold along the tangent, so at best in every direction.
std::vector<mesh::HeldDirection> best_held_directions(const Body& body, const std::vector<ContactPair>& contacts,
                                                      const std::vector<int>& its_pairs, size_t i) {
  std::vector<mesh::HeldDirection> held;
  for (const auto& bc : body.boundary) {
    if (!prescribes_displacement(bc)) continue;
    for (int node : condition_nodes(body.mesh, bc)) {
      if (bc.ux) held.push_back({node, Eigen::Vector2d(1, 0)});
      if (bc.uy) held.push_back({node, Eigen::Vector2d(0, 1)});
    }
  }
  // Each edge of the body once, however many pairs use it (a strip under 400 pairs, all on its top, would be
  // walked 400 times: pairs x nodes), with tangents too where any of its pairs has friction.
  std::map<std::string, bool> edges;  // edge -> a pair on it has friction
  for (const int k : its_pairs) {
    const ContactPair& c = contacts[static_cast<size_t>(k)];
    if (c.slave_body == static_cast<int>(i)) edges[c.slave_edge] |= c.friction.active();
    if (c.master_body == static_cast<int>(i)) edges[c.master_edge] |= c.friction.active();
  }
  for (const auto& [edge, friction] : edges) {
    // A node's normal: perpendicular to the chord through its neighbours (on a uniformly divided arc, exactly
    // radial). An end node has one neighbour: its one-sided normal is kept where the edge is straight there (it
    // equals its neighbour's), not where it is curved (it would hold a roller's spin that its end nodes, far
    // from the contact, never do). A closed loop has no ends: its nodes' neighbours wrap round.
    const std::vector<int> nodes = body.mesh.edge_set_nodes(edge);
    const size_t n = nodes.size();
    const bool closed = body.mesh.edge_set_closed(edge);
    const auto at = [&](size_t j) { return body.mesh.nodes[static_cast<size_t>(nodes[j])]; };
    const auto normal = [&](size_t j) {
      const size_t next = closed ? (j + 1) % n : std::min(j + 1, n - 1);
      const size_t previous = closed ? (j + n - 1) % n : (j == 0 ? 0 : j - 1);
      const Eigen::Vector2d t = at(next) - at(previous);
      return t.norm() > 0 ? Eigen::Vector2d(Eigen::Vector2d(-t.y(), t.x()).normalized()) : Eigen::Vector2d::Zero();
    };
    for (size_t j = 0; j < n && n > 1; ++j) {
      const Eigen::Vector2d nu = normal(j);
      if (!(nu.norm() > 0)) continue;
      const bool end = !closed && (j == 0 || j + 1 == n);
      if (end && n > 2) {
        const Eigen::Vector2d inner = normal(j == 0 ? 1 : n - 2);
        if (std::abs(nu.x() * inner.y() - nu.y() * inner.x()) > 1e-9) continue;  // curved at the end
      }
      held.push_back({nodes[j], nu});
      if (friction) held.push_back({nodes[j], Eigen::Vector2d(-nu.y(), nu.x())});
    }
  }
  return held;
}

std::string contact_names(const Problem& problem, const std::vector<int>& its_pairs) {
  std::string out;
  for (const int k : its_pairs)
    out += (out.empty() ? "'" : ", '") + problem.contacts[static_cast<size_t>(k)].name + "'";
  return out;
}

}  // namespace

// A floating body (free rigid motions) is accepted when it touches another body and the method solves the
// interface problem with its equilibrium (interface_newton, monolithic); the fixed-point schemes solve every
// body alone with Neumann data on its contact zone, which a floating body cannot take.
void JobReader::check_floating_bodies() {
  // A contact pair refused or left out (a limit, a bad reference, a bad gap) may be the one that holds a body:
  // whether a body floats is then not known, and its error would only repeat the contacts'.
  if (!contacts_complete_) return;
  const Method method = problem_.solver.method;
  std::vector<std::vector<int>> pairs_of(inputs_.size());  // each body's contact pairs, by index
  for (size_t k = 0; k < problem_.contacts.size(); ++k) {
    const ContactPair& c = problem_.contacts[k];
    for (const int b : {c.slave_body, c.master_body})
      if (b >= 0 && static_cast<size_t>(b) < pairs_of.size() &&
          (pairs_of[static_cast<size_t>(b)].empty() || pairs_of[static_cast<size_t>(b)].back() != static_cast<int>(k)))
        pairs_of[static_cast<size_t>(b)].push_back(static_cast<int>(k));
  }
  for (size_t i = 0; i < inputs_.size(); ++i) {
    if (i % 64 == 63 && out_of_time("checking the floating bodies")) return;
    const BodyInput& in = inputs_[i];
    if (in.free_motions.empty()) continue;
    const std::string free = join_names(in.free_motions) + (in.free_motions.size() == 1 ? " is" : " are") + " free";
    const bool in_contact = !pairs_of[i].empty();
    if (!in_contact) {
      errors_.add(child(in.pointer, "boundary"),
                  "body '" + in.body.name + "' is not restrained against rigid motion (" + free +
                      ") and touches no other body: prescribe a displacement component on one of its edges or "
                      "vertices, or give it a contact that can hold it");
    } else if (const auto loose = mesh::free_rigid_modes_along(
                                      in.body.mesh, best_held_directions(in.body, problem_.contacts, pairs_of[i], i))
                                      .names;
               !loose.empty()) {
      // Frictionless contacts push only along their normals: a motion no normal resists is free whatever the
      // loads (a plate sliding along a flat contact, a roller spinning about its centre, where all its normals
      // meet). The solve could only fail later and blame the loads.
      std::string modes;
      for (const auto& m : loose)
        modes += (modes.empty() ? "" : "; ") + m +
                 (m.rfind("translation", 0) == 0      ? " (it slides along them)"
                  : m.rfind("rotation about", 0) == 0 ? " (it spins: every contact normal passes through that point)"
                                                      : "");
      errors_.add(child(in.pointer, "boundary"), "body '" + in.body.name + "' floats (" + free +
                                                     ") and its frictionless contacts " +
                                                     contact_names(problem_, pairs_of[i]) +
                                                     " cannot hold it whatever the loads, since they push only along "
                                                     "their normals: nothing resists its " +
                                                     modes +
                                                     "; prescribe a displacement component that "
                                                     "stops it, on an edge or a named vertex");
    } else if (method == Method::neumann || method == Method::robin) {
      errors_.add(method_.pointer.empty() ? child(in.pointer, "boundary") : method_.pointer,
                  "body '" + in.body.name + "' floats (" + free + ": only its contacts hold it), and method \"" +
                      to_string(method) +
                      "\" solves every body on its own with contact tractions as loads, which a floating body "
                      "cannot take; use method \"interface_newton\" (the default) or \"monolithic\", or restrain "
                      "the body");
    }
  }
}

}  // namespace contact::job::detail
