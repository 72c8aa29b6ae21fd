// gmsh::surface: one physical surface of a parsed MSH file -> a body's Mesh with its physical curves as edges.
#include "gmsh.hpp"

#include "curve_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <sstream>
#include <unordered_set>

namespace contact::mesh::gmsh {

namespace {

constexpr int kLine = 1, kTriangle = 2, kQuadrangle = 3;  // Gmsh element types

std::pair<int, int> key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

double cross(const Point& a, const Point& b) { return a.x() * b.y() - a.y() * b.x(); }

// "elements 4, 7 and 9" (at most 5 listed).
std::string element_list(const std::vector<std::size_t>& tags) {
  std::ostringstream os;
  os << (tags.size() == 1 ? "element " : "elements ");
  for (size_t k = 0; k < tags.size() && k < 5; ++k)
    os << (k == 0 ? "" : k + 1 == tags.size() ? " and " : ", ") << tags[k];
  if (tags.size() > 5) os << " and " << tags.size() - 5 << " more";
  return os.str();
}

const char* is_are(const std::vector<std::size_t>& tags) { return tags.size() == 1 ? "is" : "are"; }

// "'a', 'b' and 'c'"; beyond `max` names, the first `max` and "... and N more" (a file may hold 10^5 names).
std::string quoted_list(const std::vector<std::string>& names, size_t max = 20) {
  if (names.empty()) return "(none)";
  const size_t shown = std::min(names.size(), max);
  std::string out;
  for (size_t k = 0; k < shown; ++k)
    out += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + ("'" + names[k] + "'");
  if (shown < names.size()) out += " ... and " + std::to_string(names.size() - shown) + " more";
  return out;
}

// The physical tags of dimension `dim` named `name`.
std::set<int> groups_named(const File& f, int dim, const std::string& name) {
  std::set<int> out;
  for (const auto& [group, n] : f.physical_names)
    if (group.first == dim && n == name) out.insert(group.second);
  return out;
}

// A named physical group of one dimension: its name, and the element blocks on its entities (in file order).
struct NamedGroup {
  std::string name;
  std::vector<const File::ElementBlock*> blocks;
};

// Every name of the physical groups of dimension `dim`, in the order of their (first) physical tags, with the
// blocks on its entities. One pass over the names and one over the entities and blocks, each step a lookup: a
// file with 10^5 names or blocks costs linear time, not names x names or names x blocks.
std::vector<NamedGroup> named_groups(const File& f, int dim) {
  std::vector<NamedGroup> out;
  std::unordered_map<std::string, size_t> by_name;
  std::unordered_map<int, size_t> by_tag;  // physical tag -> index into out
  for (const auto& [group, n] : f.physical_names) {
    if (group.first != dim) continue;
    const auto [it, added] = by_name.emplace(n, out.size());
    if (added) out.push_back({n, {}});
    by_tag[group.second] = it->second;
  }
  std::map<int, std::set<size_t>> of_entity;  // entity -> the groups it is in
  for (const auto& [entity, tags] : f.entity_groups) {
    if (entity.first != dim) continue;
    for (int tag : tags)
      if (auto g = by_tag.find(tag); g != by_tag.end()) of_entity[entity.second].insert(g->second);
  }
  for (const auto& b : f.blocks) {
    if (b.dim != dim) continue;
    if (auto e = of_entity.find(b.entity); e != of_entity.end())
      for (size_t g : e->second) out[g].blocks.push_back(&b);
  }
  return out;
}

// The entities of dimension `dim` in any of the physical groups `groups`.
std::set<int> entities_in(const File& f, int dim, const std::set<int>& groups) {
  std::set<int> out;
  for (const auto& [entity, tags] : f.entity_groups)
    if (entity.first == dim && std::any_of(tags.begin(), tags.end(), [&](int g) { return groups.count(g) > 0; }))
      out.insert(entity.second);
  return out;
}

// The cells of the surface: node tags per cell and element tags, with the problems of element types.
struct RawCells {
  std::vector<std::vector<std::size_t>> nodes;
  std::vector<std::size_t> tags;
};

RawCells collect_cells(const File& f, const std::set<int>& groups, const std::string& name,
                       std::vector<std::string>& errors) {
  RawCells raw;
  std::map<int, std::vector<std::size_t>> unsupported;  // type -> element tags
  const std::set<int> entities = entities_in(f, 2, groups);
  for (const auto& b : f.blocks) {
    if (b.dim != 2 || !entities.count(b.entity)) continue;
    if (b.type != kTriangle && b.type != kQuadrangle) {
      auto& list = unsupported[b.type];
      list.insert(list.end(), b.tags.begin(), b.tags.end());
      continue;
    }
    const size_t expected = b.type == kTriangle ? 3 : 4;  // parse() checked each element's count
    for (size_t k = 0; k < b.tags.size(); ++k) {
      if (std::set<std::size_t>(b.nodes[k].begin(), b.nodes[k].end()).size() != expected) {
        errors.push_back(element_list({b.tags[k]}) + " of surface '" + name + "' repeats a node");
        continue;
      }
      raw.nodes.push_back(b.nodes[k]);
      raw.tags.push_back(b.tags[k]);
    }
  }
  for (const auto& [type, tags] : unsupported)
    errors.push_back(element_list(tags) + " of surface '" + name + "' " + is_are(tags) + " " +
                     (tags.size() == 1 ? "a " : "") + element_type_name(type) + (tags.size() == 1 ? "" : "s") +
                     ", which " + is_are(tags) +
                     " not supported: only 3-node triangles and 4-node quadrangles (first-order elements: "
                     "Mesh.ElementOrder = 1, the default)");
  return raw;
}

// Degenerate, inverted and non-convex cells, by the signs of the corner cross products. A surface whose cells
// all run clockwise (meshed with its normal along -z) is reversed; cells of both orientations are an error.
void orient_and_check(Mesh& m, const std::vector<std::size_t>& tags, const std::string& name,
                      std::vector<std::string>& errors) {
  std::vector<std::size_t> degenerate, clockwise, counter, concave;
  std::vector<int> sign(m.cells.size(), 0);
  for (size_t c = 0; c < m.cells.size(); ++c) {
    const Cell& q = m.cells[c];
    const int n = q.size();
    auto at = [&](int k) -> const Point& { return m.nodes[static_cast<size_t>(q[static_cast<size_t>(k % n)])]; };
    double scale = 0;
    for (int k = 0; k < n; ++k) scale = std::max(scale, (at(k + 1) - at(k)).squaredNorm());
    const double area = m.cell_area(static_cast<int>(c));
    if (!(scale > 0) || std::abs(area) <= 1e-12 * scale) {
      degenerate.push_back(tags[c]);
      continue;
    }
    sign[c] = area > 0 ? 1 : -1;
    (area > 0 ? counter : clockwise).push_back(tags[c]);
    for (int k = 0; k < n; ++k)
      if (sign[c] * cross(at(k + 1) - at(k), at(k + n - 1) - at(k)) <= 1e-12 * scale) {
        concave.push_back(tags[c]);
        break;
      }
  }
  if (!degenerate.empty())
    errors.push_back(element_list(degenerate) + " of surface '" + name + "' " + is_are(degenerate) +
                     " degenerate (zero area)");
  if (!concave.empty())
    errors.push_back(element_list(concave) + " of surface '" + name + "' " + is_are(concave) +
                     " degenerate or not convex at a corner (a quadrangle must be convex)");
  if (!clockwise.empty() && !counter.empty()) {
    const bool fewer_clockwise = clockwise.size() <= counter.size();
    const auto& odd = fewer_clockwise ? clockwise : counter;
    errors.push_back(element_list(odd) + " of surface '" + name + "' " + is_are(odd) +
                     " inverted: " + (odd.size() == 1 ? "its" : "their") + " nodes run " +
                     (fewer_clockwise ? "clockwise" : "counter-clockwise") + " while the other " +
                     std::to_string((fewer_clockwise ? counter : clockwise).size()) + " cells run the other way");
  } else if (!clockwise.empty()) {
    for (auto& q : m.cells) std::reverse(q.begin() + 1, q.end());  // (a, b, c, d) -> (a, d, c, b)
  }
}

// Sides shared by more than two cells, and a body in more than one piece. Returns the number of cells at each side.
std::map<std::pair<int, int>, int> check_topology(const Mesh& m, const std::vector<std::size_t>& tags,
                                                  const std::string& name, std::vector<std::string>& errors) {
  std::map<std::pair<int, int>, int> count;
  std::map<std::pair<int, int>, int> first;  // side -> its first cell
  std::vector<std::size_t> crowded;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      const auto side = key(n[0], n[1]);
      first.emplace(side, c);
      if (++count[side] == 3) crowded.push_back(tags[static_cast<size_t>(first[side])]);
    }
  if (!crowded.empty())
    errors.push_back("surface '" + name + "' has sides shared by more than two cells (at " + element_list(crowded) +
                     "): it is not a plane mesh");
  const std::vector<int> piece = pieces(m);
  std::vector<std::size_t> detached;
  for (size_t c = 0; c < piece.size(); ++c)
    if (piece[c] != 0) detached.push_back(tags[c]);
  if (!detached.empty())
    errors.push_back("surface '" + name + "' is not one piece: " + element_list(detached) + " " + is_are(detached) +
                     " not connected to element " + std::to_string(tags.front()) +
                     " through shared sides (a body must be one piece: make each piece its own physical surface)");
  return count;
}

// Physical curves: their 2-node lines on this surface's boundary become edge sets.
void add_curves(const File& f, const std::unordered_map<std::size_t, int>& local,
                const std::map<std::pair<int, int>, int>& side_count, const std::string& name, Surface& out) {
  for (const auto& [curve, blocks] : named_groups(f, 1)) {
    std::vector<std::array<int, 2>> pairs;
    std::vector<std::size_t> interior, second_order;
    for (const File::ElementBlock* block : blocks) {
      const auto& b = *block;
      for (size_t k = 0; k < b.tags.size(); ++k) {
        const auto& nodes = b.nodes[k];  // a line's two end nodes come first, whatever its order
        if (nodes.size() < 2) continue;
        auto a = local.find(nodes[0]), z = local.find(nodes[1]);
        if (a == local.end() || z == local.end()) continue;  // not on this surface
        auto side = side_count.find(key(a->second, z->second));
        if (b.type != kLine) {
          if (side != side_count.end()) second_order.push_back(b.tags[k]);
          continue;
        }
        if (side == side_count.end()) continue;
        if (side->second != 1)
          interior.push_back(b.tags[k]);
        else
          pairs.push_back({a->second, z->second});
      }
    }
    const std::string what = "physical curve '" + curve + "' on surface '" + name + "'";
    if (!second_order.empty())
      out.errors.push_back(what + ": " + element_list(second_order) + " " + is_are(second_order) +
                           " not 2-node lines (first-order elements only: Mesh.ElementOrder = 1)");
    if (!interior.empty())
      out.errors.push_back(what + " runs through the surface's interior (" + element_list(interior) +
                           "): an edge must lie on the body's boundary");
    if (pairs.empty()) {
      if (second_order.empty() && interior.empty()) out.elsewhere.push_back(curve);
      continue;
    }
    if (auto problem = add_edge_set(out.mesh, curve, pairs))
      out.errors.push_back(what + ": " + *problem);
    else
      out.edges.push_back(curve);
  }
}

// Physical points: one whose point lies on this surface (a node of its mesh) becomes a named vertex.
void add_points(const File& f, const std::unordered_map<std::size_t, int>& local, const std::string& name,
                Surface& out) {
  for (const auto& [point, blocks] : named_groups(f, 0)) {
    std::set<int> nodes;  // this surface's nodes among the point's
    for (const File::ElementBlock* b : blocks) {
      for (const auto& element : b->nodes)
        for (std::size_t tag : element) {
          auto it = local.find(tag);
          if (it != local.end()) nodes.insert(it->second);
        }
    }
    if (nodes.empty()) {
      out.points_elsewhere.push_back(point);
    } else if (nodes.size() > 1) {
      out.errors.push_back("physical point '" + point + "' has " + std::to_string(nodes.size()) +
                           " points on surface '" + name + "': a vertex is one point (give each its own name)");
    } else {
      out.mesh.vertices[point] = *nodes.begin();
      out.vertices.push_back(point);
    }
  }
}

// A curve entity's lines in order along it (node tags, the first again at the end of a closed curve), or empty
// where they do not form one chain.
std::vector<std::size_t> in_order(const std::vector<std::array<std::size_t, 2>>& segments) {
  std::map<std::size_t, std::size_t> next;
  std::set<std::size_t> ends;
  for (const auto& s : segments)
    if (!next.emplace(s[0], s[1]).second) return {};  // a fork
  for (const auto& s : segments) ends.insert(s[1]);
  std::size_t first = segments.front()[0];
  for (const auto& s : segments)
    if (!ends.count(s[0])) first = s[0];
  std::vector<std::size_t> out = {first};
  while (out.size() <= segments.size()) {
    const auto n = next.find(out.back());
    if (n == next.end()) break;
    out.push_back(n->second);
    if (n->second == first) break;
  }
  return out.size() == segments.size() + 1 ? out : std::vector<std::size_t>{};
}

// The boundary sides of a curve entity that is neither straight nor a circle (a spline, an ellipse) get the local
// arcs of mesh/curve_fit.hpp, a smooth description for the contact's gaps and normals and for refinement's new nodes.
void add_fitted_arcs(const File& f, const std::vector<std::array<std::size_t, 2>>& segments,
                     const std::unordered_map<std::size_t, int>& local,
                     const std::map<std::pair<int, int>, int>& side_count, Mesh& m) {
  std::vector<std::size_t> tags = in_order(segments);
  if (tags.empty()) return;
  const bool closed = tags.front() == tags.back();
  if (closed) tags.pop_back();
  std::vector<Point> x;
  for (std::size_t tag : tags) x.push_back(f.nodes[f.node_index.at(tag)].xy);
  const auto arcs = fitted_arcs(x, closed);
  for (size_t k = 0; k < arcs.size(); ++k) {
    auto i = local.find(tags[k]), j = local.find(tags[(k + 1) % tags.size()]);
    if (!arcs[k] || i == local.end() || j == local.end()) continue;
    auto side = side_count.find(key(i->second, j->second));
    if (side != side_count.end() && side->second == 1) m.side_curves[key(i->second, j->second)] = *arcs[k];
  }
}

// The circle through all the nodes of each curve entity's lines, where there is one (Gmsh's Circle and
// Ellipse arcs with equal axes): the boundary sides on it get it as their true geometry, so that refinement puts
// new nodes on the arc rather than on the chord, and the contact measures its gaps and normals on it. Other curves
// get fitted local arcs (add_fitted_arcs); straight ones are left to their chords.
void add_arcs(const File& f, const std::unordered_map<std::size_t, int>& local,
              const std::map<std::pair<int, int>, int>& side_count, Mesh& m) {
  std::map<int, std::vector<std::array<std::size_t, 2>>> lines;  // curve entity -> its lines' end nodes
  for (const auto& b : f.blocks)
    if (b.dim == 1 && b.type == kLine)
      for (const auto& nodes : b.nodes) lines[b.entity].push_back({nodes[0], nodes[1]});
  for (const auto& [entity, segments] : lines) {
    if (segments.size() < 2) continue;
    std::vector<Point> x;
    for (const auto& s : segments)
      for (std::size_t tag : s) x.push_back(f.nodes[f.node_index.at(tag)].xy);
    // Three nodes far apart: the first, the farthest from it, and the farthest from the line through both.
    const Point a = x.front();
    Point c = a, b = a;
    for (const auto& p : x)
      if ((p - a).squaredNorm() > (c - a).squaredNorm()) c = p;
    const double chord = (c - a).norm();
    if (!(chord > 0)) continue;
    double offset = 0;
    for (const auto& p : x) {
      const double d = std::abs(cross(c - a, p - a)) / chord;
      if (d > offset) offset = d, b = p;
    }
    if (offset <= 1e-9 * chord) continue;  // straight
    // The circumcentre of a, b, c.
    const Point ab = b - a, ac = c - a;
    const double det = 2 * cross(ab, ac);
    const Point centre = a + Point(ac.y() * ab.squaredNorm() - ab.y() * ac.squaredNorm(),
                                   ab.x() * ac.squaredNorm() - ac.x() * ab.squaredNorm()) /
                                 det;
    const double radius = (a - centre).norm();
    if (!std::all_of(x.begin(), x.end(),
                     [&](const Point& p) { return std::abs((p - centre).norm() - radius) <= 1e-8 * radius; })) {
      add_fitted_arcs(f, segments, local, side_count, m);  // not a circle
      continue;
    }
    Curve arc;
    arc.kind = Curve::Kind::arc;
    arc.center = centre;
    arc.radius = radius;
    for (const auto& s : segments) {
      auto i = local.find(s[0]), j = local.find(s[1]);
      if (i == local.end() || j == local.end()) continue;
      auto side = side_count.find(key(i->second, j->second));
      if (side != side_count.end() && side->second == 1) m.side_curves[key(i->second, j->second)] = arc;
    }
  }
}

}  // namespace

Surface surface(const File& f, const std::string& name) {
  Surface out;
  const std::set<int> groups = groups_named(f, 2, name);
  if (groups.empty()) {
    std::vector<std::string> surfaces;  // each name once, in the order of its first physical tag
    std::unordered_set<std::string> seen;
    std::string other_kind;
    for (const auto& [group, n] : f.physical_names) {
      if (group.first == 2 && seen.insert(n).second) surfaces.push_back(n);
      if (group.first != 2 && n == name)
        other_kind = group.first == 1 ? "curve" : group.first == 0 ? "point" : "volume";
    }
    out.errors.push_back(
        (other_kind.empty() ? "the file has no physical surface '" + name + "'"
                            : "'" + name + "' is a physical " + other_kind + ", not a physical surface") +
        "; its physical surfaces are " + quoted_list(surfaces) +
        (surfaces.empty() ? " (name them in the .geo file: Physical Surface(\"name\") = {...};)" : ""));
    return out;
  }
  out.found = true;
  const RawCells raw = collect_cells(f, groups, name, out.errors);
  if (raw.nodes.empty()) {
    if (out.errors.empty())
      out.errors.push_back("physical surface '" + name + "' has no elements (was the file meshed in 2-D?)");
    return out;
  }
  // Nodes renumbered from 0 in the order of their tags.
  std::vector<std::size_t> node_tags;
  for (const auto& cell : raw.nodes) node_tags.insert(node_tags.end(), cell.begin(), cell.end());
  std::sort(node_tags.begin(), node_tags.end());
  node_tags.erase(std::unique(node_tags.begin(), node_tags.end()), node_tags.end());
  std::unordered_map<std::size_t, int> local;
  Mesh& m = out.mesh;
  double z_min = 0, z_max = 0, extent = 0;
  for (size_t k = 0; k < node_tags.size(); ++k) {
    const File::Node& node = f.nodes[f.node_index.at(node_tags[k])];
    local[node_tags[k]] = static_cast<int>(k);
    m.nodes.push_back(node.xy);
    z_min = k == 0 ? node.z : std::min(z_min, node.z);
    z_max = k == 0 ? node.z : std::max(z_max, node.z);
  }
  extent = (m.bbox_max() - m.bbox_min()).norm();
  if (z_max - z_min > 1e-9 * std::max(extent, 1e-300)) {
    std::ostringstream os;
    os << "surface '" << name << "' is not in a plane z = const (z from " << z_min << " to " << z_max
       << "): the solver is 2-D, in the x-y plane";
    out.errors.push_back(os.str());
    return out;
  }
  for (const auto& cell : raw.nodes) {
    std::vector<int> n;
    for (std::size_t tag : cell) n.push_back(local.at(tag));
    if (n.size() == 3)
      m.cells.emplace_back(n[0], n[1], n[2]);
    else
      m.cells.emplace_back(n[0], n[1], n[2], n[3]);
  }
  m.level.assign(m.cells.size(), 0);
  if (!out.errors.empty()) return out;
  orient_and_check(m, raw.tags, name, out.errors);
  if (!out.errors.empty()) return out;
  const auto side_count = check_topology(m, raw.tags, name, out.errors);
  if (!out.errors.empty()) return out;
  add_curves(f, local, side_count, name, out);
  add_points(f, local, name, out);
  add_arcs(f, local, side_count, out.mesh);
  return out;
}

}  // namespace contact::mesh::gmsh
