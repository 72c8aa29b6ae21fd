// A body's mesh: a block (corners, curved edges, grading), explicit nodes, quads, edges and vertices, or a Gmsh
// surface (gmsh_input.hpp). Read in phase 1 (sizes and edge names known), built and checked in phase 3.
#include "job_reader.hpp"

#include "mesh/curve_fit.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace contact::job::detail {

namespace {
const char* const kBlockEdges[] = {"bottom", "right", "top", "left"};
}  // namespace

bool has_edge(const MeshInput& m, const std::string& name) {
  return std::find(m.edge_names.begin(), m.edge_names.end(), name) != m.edge_names.end();
}

std::optional<std::string> gmsh_elsewhere(const MeshInput& m, const std::string& name, bool vertex) {
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

void JobReader::read_mesh(const json& value, const std::string& pointer, MeshInput& m, json& out) {
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
    read_gmsh(value.at("gmsh"), child(pointer, "gmsh"), m, sub_object(out, "gmsh"));
    return;
  }
  const bool block = value.contains("block");
  const bool arrays =
      value.contains("nodes") || value.contains("quads") || value.contains("edges") || value.contains("vertices");
  if (block == arrays) {
    Fields f(value, pointer, "mesh", {"block", "nodes", "quads", "edges", "vertices", "curves"}, errors_);
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

void JobReader::read_block(const json& value, const std::string& pointer, MeshInput& m) {
  m.kind = MeshInput::Kind::block;
  m.edges_known = true;
  m.edge_names = {"bottom", "right", "top", "left"};
  m.vertex_names = {"bottom_left", "bottom_right", "top_right", "top_left"};
  const size_t before = errors_.size();
  Fields f(value, pointer, "block", {"corners", "nx", "ny", "edges", "grading"}, errors_);
  if (!f.ok()) return;
  const bool corners_ok = read_block_corners(f, m.block);
  read_block_size(f, m);
  if (const json* e = f.find("edges")) {
    Fields edges(*e, f.at("edges"), "block edges", {"bottom", "right", "top", "left"}, errors_);
    for (const char* name : kBlockEdges)
      if (const json* c = edges.find(name))
        if (auto curve = read_curve(*c, edges.at(name), name, m)) m.block.curves[name] = *curve;
  }
  if (const json* g = f.find("grading")) read_block_grading(*g, f.at("grading"), m.block);
  if (corners_ok) fit_block_curves(m);
  m.valid = errors_.size() == before;
}

// The block's four corners, counter-clockwise; false (reported) unless all four are read and enclose an area.
bool JobReader::read_block_corners(const Fields& f, mesh::BlockSpec& spec) {
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
  return corners_ok;
}

// nx and ny, and the DOF count they give.
void JobReader::read_block_size(const Fields& f, MeshInput& m) {
  mesh::BlockSpec& spec = m.block;
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
}

// Grading ratios towards named edges, at most one per direction.
void JobReader::read_block_grading(const json& value, const std::string& pointer, mesh::BlockSpec& spec) {
  Fields grading(value, pointer, "grading", {"bottom", "right", "top", "left"}, errors_);
  for (const char* name : kBlockEdges)
    if (const json* r = grading.find(name))
      if (auto x = positive(*r, grading.at(name), std::string("grading ratio towards ") + name, errors_))
        spec.grading[name] = *x;
  if (grading.has("bottom") && grading.has("top"))
    errors_.add(pointer,
                "grading towards both bottom and top: give at most one of them per direction "
                "(the ratio grades the whole block from the named edge)");
  if (grading.has("left") && grading.has("right"))
    errors_.add(pointer,
                "grading towards both left and right: give at most one of them per direction "
                "(the ratio grades the whole block from the named edge)");
}

// Fit the curves to the corners they join (the order matches make_block's parametrisation).
void JobReader::fit_block_curves(MeshInput& m) {
  const auto& P = m.block.corners;
  const std::map<std::string, std::pair<Point, Point>> ends = {
      {"bottom", {P[0], P[1]}}, {"right", {P[1], P[2]}}, {"top", {P[3], P[2]}}, {"left", {P[0], P[3]}}};
  for (auto& [name, curve] : m.block.curves) {
    const auto& [p, q] = ends.at(name);
    if (auto message = mesh::fit_curve(curve, p, q)) errors_.add(m.curve_pointers.at(name), *message);
  }
}

// {"gmsh": {...}}: the file (or data) is read and the surface's mesh built here, so that its edge names are
// known to the boundary conditions and contacts; its size counts in the limit like any other mesh's.
void JobReader::read_gmsh(const json& value, const std::string& pointer, MeshInput& m, json& out) {
  m.kind = MeshInput::Kind::gmsh;
  const size_t before = errors_.size();
  m.gmsh = gmsh_.read(value, pointer, errors_, out);
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

std::optional<long long> JobReader::read_count(const json& value, const std::string& pointer, const std::string& what) {
  auto n = read::integer(value, pointer, what, errors_);
  if (n && *n < 1) {
    errors_.add(pointer, what + " = " + std::to_string(*n) + " must be at least 1");
    return std::nullopt;
  }
  return n;
}

std::optional<mesh::Curve> JobReader::read_curve(const json& value, const std::string& pointer, const std::string& edge,
                                                 MeshInput& m) {
  Fields f(value, pointer, "the curve of edge " + edge, {"parabola", "arc"}, errors_);
  if (!f.ok()) return std::nullopt;
  if (f.has("parabola") == f.has("arc")) {
    errors_.add(pointer, "give exactly one of parabola {\"a\": ...} or arc {\"center\": [x, y], \"radius\": R}");
    return std::nullopt;
  }
  mesh::Curve curve;
  if (const json* p = f.find("parabola")) {
    Fields pf(*p, f.at("parabola"), "parabola", {"a"}, errors_);
    m.curve_pointers[edge] = f.at("parabola");
    curve.kind = mesh::Curve::Kind::parabola;
    const json* a = pf.require("a", "the coefficient a of y = a x^2 + b x + c (b and c follow from the corners)");
    if (!a) return std::nullopt;
    auto x = read::number(*a, pf.at("a"), "a", errors_);
    if (!x) return std::nullopt;
    curve.a = *x;
  } else {
    const json* arc = f.find("arc");
    Fields af(*arc, f.at("arc"), "arc", {"center", "radius"}, errors_);
    m.curve_pointers[edge] = f.at("arc");
    curve.kind = mesh::Curve::Kind::arc;
    const json* c = af.require("center", "the circle's centre [x, y]");
    const json* r = af.require("radius", "the circle's radius, a positive number");
    if (!c || !r) return std::nullopt;
    auto centre = read::pair(*c, af.at("center"), "center", errors_);
    auto radius = positive(*r, af.at("radius"), "radius", errors_);
    if (!centre || !radius) return std::nullopt;
    curve.center = *centre;
    curve.radius = *radius;
  }
  return curve;
}

// A side listed twice in one edge set (in either direction) would carry its load twice: an error at the
// second listing, naming the first.
bool JobReader::no_side_twice(const std::string& name, const std::vector<std::array<int, 2>>& pairs,
                              const std::string& pointer) {
  std::map<std::pair<int, int>, size_t> first;
  bool ok = true;
  for (size_t k = 0; k < pairs.size(); ++k) {
    const auto [i, j] = pairs[k];
    auto [it, inserted] = first.emplace(std::make_pair(std::min(i, j), std::max(i, j)), k);
    if (inserted) continue;
    errors_.add(child(pointer, k), "the side [" + std::to_string(i) + ", " + std::to_string(j) + "] of edge '" + name +
                                       "' is already listed at " + child(pointer, it->second) +
                                       " (a side listed twice would carry its load twice)");
    ok = false;
  }
  return ok;
}

template <typename Index>
void JobReader::read_edge_set(const std::string& name, const json& value, const std::string& pointer, bool nodes_ok,
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

std::optional<int> NodeIndex::operator()(const json& v, const std::string& ptr, const std::string& what) const {
  auto n = read::integer(v, ptr, what, errors);
  if (!n) return std::nullopt;
  if (*n < 0 || *n >= static_cast<long long>(node_count)) {
    errors.add(ptr, what + " = " + std::to_string(*n) + " is out of range: the mesh has " + std::to_string(node_count) +
                        " nodes, indices 0.." + std::to_string(node_count - 1));
    return std::nullopt;
  }
  return static_cast<int>(*n);
}

void JobReader::read_arrays(const json& value, const std::string& pointer, MeshInput& m, json& out) {
  m.kind = MeshInput::Kind::arrays;
  const size_t before = errors_.size();
  Fields f(value, pointer, "mesh", {"nodes", "quads", "edges", "vertices", "curves"}, errors_);
  const json* nodes = f.require("nodes", "an array of points [[x, y], ...], or use {\"block\": {...}}");
  const json* quads = f.require("quads", "an array of quads [[i, j, k, l], ...] (node indices, counter-clockwise)");
  const size_t before_nodes = errors_.size();
  const size_t node_count = nodes ? read_nodes(*nodes, f.at("nodes"), m) : 0;
  // Indices are checked against the nodes only when those were read cleanly.
  const bool nodes_ok = nodes && node_count > 0 && errors_.size() == before_nodes;
  const NodeIndex index{node_count, errors_};
  if (quads && nodes_ok) read_quads(*quads, f.at("quads"), index, m);
  read_named_edges(f, nodes_ok, index, m, out);
  read_named_vertices(f, nodes_ok, index, m, out);
  read_edge_curves(f, m, out);
  m.valid = errors_.size() == before && nodes_ok && !m.quads.empty();
}

// An explicit mesh's "nodes": their count (0 if not a non-empty array), and the points unless the mesh is over
// the DOF limit (refused anyway, so the coordinates are not read).
size_t JobReader::read_nodes(const json& nodes, const std::string& pointer, MeshInput& m) {
  if (!nodes.is_array() || nodes.empty()) {
    errors_.add(pointer, "nodes must be a non-empty array of points [x, y]");
    return 0;
  }
  const size_t node_count = nodes.size();
  m.dofs = 2.0 * static_cast<double>(node_count);
  if (m.dofs <= static_cast<double>(limits_.max_dofs)) {
    m.nodes.reserve(node_count);
    for (size_t k = 0; k < node_count; ++k) {
      auto p = read::pair(nodes[k], child(pointer, k), "node " + std::to_string(k), errors_);
      m.nodes.push_back(p.value_or(Point::Zero()));
    }
  }
  return node_count;
}

// An explicit mesh's "quads": four distinct node indices each; the bad ones are reported and left out.
void JobReader::read_quads(const json& quads, const std::string& pointer, const NodeIndex& index, MeshInput& m) {
  if (!quads.is_array() || quads.empty()) {
    errors_.add(pointer, "quads must be a non-empty array of [i, j, k, l]");
    return;
  }
  for (size_t q = 0; q < quads.size(); ++q) {
    const json& quad = quads[q];
    const std::string qp = child(pointer, q);
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

// An explicit mesh's "edges" {"name": [[i, j], ...]} (default: none).
void JobReader::read_named_edges(const Fields& f, bool nodes_ok, const NodeIndex& index, MeshInput& m, json& out) {
  const json* e = f.find("edges");
  if (!e) {
    m.edges_known = true;
    set_default(out, "edges", json::object());
    return;
  }
  // Edge names are the user's own, so there is no fixed key set to check against.
  if (!e->is_object()) {
    errors_.add(f.at("edges"), "edges must be an object {\"name\": [[i, j], ...], ...}, got " + read::type_name(*e));
    return;
  }
  m.edges_known = true;
  for (const auto& item : e->items())
    read_edge_set(item.key(), item.value(), child(f.at("edges"), item.key()), nodes_ok, index, m);
}

// An explicit mesh's "curves" {"edge": "fitted" | "chords" | {"arc": {...}} | {"parabola": {...}}}: the geometry
// its contacts measure gaps and normals on and refinement puts new boundary nodes on (docs/job-format.md). An
// edge not listed is "fitted" (mesh/curve_fit.hpp), and the normalized job says so.
void JobReader::read_edge_curves(const Fields& f, MeshInput& m, json& out) {
  const json* c = f.find("curves");
  if (c && !c->is_object()) {
    errors_.add(f.at("curves"),
                "curves must be an object {\"edge\": \"fitted\" | \"chords\" | {\"arc\": ...} | "
                "{\"parabola\": ...}}, got " +
                    read::type_name(*c));
    return;
  }
  json& normalized = sub_object(out, "curves");
  if (c)
    for (const auto& item : c->items()) {
      const std::string pointer = child(f.at("curves"), item.key());
      if (!has_edge(m, item.key())) {
        errors_.add(pointer, "'" + item.key() + "' is not an edge of this mesh" +
                                 (m.edge_names.empty() ? std::string(" (it names no edges)")
                                                       : "; its edges are " + join_names(m.edge_names)));
        continue;
      }
      const json& v = item.value();
      if (v.is_string()) {
        const std::string how = v.get<std::string>();
        if (how == "chords")
          m.chord_edges.insert(item.key());
        else if (how != "fitted")
          errors_.add(pointer,
                      "unknown curve \"" + how +
                          "\": give \"fitted\" (a smooth curve through the edge's nodes), "
                          "\"chords\" (the straight sides as they are), {\"arc\": {\"center\": [x, y], \"radius\": R}} "
                          "or {\"parabola\": {\"a\": a}}");
      } else if (auto curve = read_curve(v, pointer, item.key(), m)) {
        m.edge_curves[item.key()] = *curve;
      }
    }
  for (const auto& name : m.edge_names)
    if (!normalized.contains(name)) normalized[name] = "fitted";
}

// An explicit mesh's named vertices {"name": node index}: where point loads and point supports go (default: none).
void JobReader::read_named_vertices(const Fields& f, bool nodes_ok, const NodeIndex& index, MeshInput& m, json& out) {
  const json* v = f.find("vertices");
  if (!v) {
    set_default(out, "vertices", json::object());
    return;
  }
  if (!v->is_object()) {
    errors_.add(f.at("vertices"), "vertices must be an object {\"name\": node index, ...}, got " + read::type_name(*v));
    return;
  }
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

void JobReader::build_mesh(BodyInput& in) {
  const std::string mp = child(in.pointer, "mesh");
  MeshInput& m = in.mesh;
  mesh::Mesh& mesh = in.body.mesh;
  if (m.kind == MeshInput::Kind::block) {
    mesh = mesh::make_block(m.block);
  } else if (m.kind == MeshInput::Kind::gmsh) {
    mesh = m.gmsh->mesh;  // checked while reading (cells and edges, with Gmsh's element tags)
  } else {
    mesh.nodes = std::move(m.nodes);
    mesh.cells = std::move(m.quads);
    mesh.level.assign(mesh.cells.size(), 0);
    // An edge's order follows its cells' sides: only for valid cells (an inverted cell is the error to report).
    if (mesh::check_cells(mesh).empty())
      for (const auto& [name, pairs] : m.edge_pairs)
        if (auto message = mesh::add_edge_set(mesh, name, pairs))
          errors_.add(child(child(mp, "edges"), name), "edge '" + name + "': " + *message);
    fit_explicit_curves(m, mp, mesh);
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

// Explicit meshes: each named edge's geometry, as its "curves" entry says (read_edge_curves).
void JobReader::fit_explicit_curves(const MeshInput& m, const std::string& pointer, mesh::Mesh& mesh) {
  for (const auto& [name, sides] : mesh.edge_sets) {
    if (m.chord_edges.count(name)) continue;
    const auto given = m.edge_curves.find(name);
    if (given == m.edge_curves.end()) {
      mesh::fit_edge_curves(mesh, name);
    } else if (auto message = mesh::set_edge_curve(mesh, name, given->second)) {
      errors_.add(m.curve_pointers.count(name) ? m.curve_pointers.at(name) : child(child(pointer, "curves"), name),
                  "edge '" + name + "': " + *message);
    }
  }
}

// Explicit meshes only (a block is one piece by construction): every node belongs to a quad, and the quads
// form one piece joined through shared sides. Either fault leaves the stiffness matrix singular.
void JobReader::check_arrays(const mesh::Mesh& mesh, const std::string& pointer) {
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

}  // namespace contact::job::detail
