#include "pair_group.hpp"

#include "edge_curves.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

namespace contact::mortar {

namespace {

// The outward normal of an edge at one of its end nodes: its curve's there, or its end segment's chord's.
Eigen::Vector2d end_normal(const mesh::Mesh& mesh, const std::string& edge, bool at_front) {
  const std::vector<int> nodes = mesh.edge_set_nodes(edge);
  const std::vector<int> side =
      at_front ? std::vector<int>{nodes[0], nodes[1]} : std::vector<int>{nodes[nodes.size() - 2], nodes.back()};
  return EdgeCurves::of_edge(mesh, edge, side).at(0, at_front ? 0.0 : 1.0).normal;
}

// Whether edge b continues edge a (a's last node is b's first) without a corner: their normals there within 10
// degrees (a corner, a block's bottom turning into its side, keeps a multiplier per edge and normal).
bool continues(const mesh::Mesh& mesh, const std::string& a, const std::string& b) {
  const std::vector<int> na = mesh.edge_set_nodes(a), nb = mesh.edge_set_nodes(b);
  if (na.size() < 2 || nb.size() < 2 || na.back() != nb.front()) return false;
  if (mesh.edge_set_closed(a) || mesh.edge_set_closed(b)) return false;
  const Eigen::Vector2d u = end_normal(mesh, a, false), v = end_normal(mesh, b, true);
  return u.dot(v) > std::cos(10.0 * 3.14159265358979323846 / 180.0);
}

// The edges reachable from `first` through continuations among `candidates` (either direction).
std::set<std::string> connected(const mesh::Mesh& mesh, const std::string& first,
                                const std::set<std::string>& candidates) {
  std::set<std::string> out = {first};
  for (bool grew = true; grew;) {
    grew = false;
    for (const auto& e : candidates) {
      if (out.count(e)) continue;
      for (const auto& f : out)
        if (continues(mesh, e, f) || continues(mesh, f, e)) {
          out.insert(e);
          grew = true;
          break;
        }
    }
  }
  return out;
}

// The edges chained end to end into one polyline; nullopt if they do not form one chain.
std::optional<Chain> chain(const mesh::Mesh& mesh, const std::set<std::string>& edges) {
  Chain c;
  if (edges.size() == 1) {
    c.edges = {*edges.begin()};
    c.start = {0};
    c.nodes = mesh.edge_set_nodes(c.edges[0]);
    c.closed = mesh.edge_set_closed(c.edges[0]);
    return c;
  }
  // The first edge: one that continues no other (a closed chain of edges has none: any).
  std::string current = *edges.begin();
  for (const auto& e : edges)
    if (std::none_of(edges.begin(), edges.end(), [&](const std::string& f) { return continues(mesh, f, e); }))
      current = e;
  while (c.edges.size() < edges.size()) {
    c.edges.push_back(current);
    c.start.push_back(c.nodes.empty() ? 0 : c.nodes.size() - 1);
    const std::vector<int> nodes = mesh.edge_set_nodes(current);
    c.nodes.insert(c.nodes.end(), nodes.begin() + (c.nodes.empty() ? 0 : 1), nodes.end());
    const auto next =
        std::find_if(edges.begin(), edges.end(), [&](const std::string& f) { return continues(mesh, current, f); });
    if (c.edges.size() == edges.size()) break;
    if (next == edges.end() || std::count(c.edges.begin(), c.edges.end(), *next))
      return std::nullopt;  // a gap or a fork
    current = *next;
  }
  if (continues(mesh, c.edges.back(), c.edges.front())) {  // the last edge closes the loop
    c.closed = true;
    c.nodes.pop_back();
  }
  return c;
}

}  // namespace

size_t Chain::edge_of_segment(size_t k) const {
  const auto after = std::upper_bound(start.begin(), start.end(), k);
  return static_cast<size_t>(after - start.begin()) - 1;
}

size_t Chain::index(const std::string& edge) const {
  return static_cast<size_t>(std::find(edges.begin(), edges.end(), edge) - edges.begin());
}

int PairGroup::pair_of(size_t s, size_t m) const {
  return s < by_edges.size() && m < by_edges[s].size() ? by_edges[s][m] : -1;
}

PairGroup pair_group(const Problem& problem, int pair_index, const ContactIndex* index) {
  const ContactIndex own = index ? ContactIndex{} : ContactIndex(problem);
  const ContactIndex& by_body = index ? *index : own;
  const ContactPair& pair = problem.contacts[static_cast<size_t>(pair_index)];
  const mesh::Mesh& slave = problem.bodies[static_cast<size_t>(pair.slave_body)].mesh;
  const mesh::Mesh& master = problem.bodies[static_cast<size_t>(pair.master_body)].mesh;
  // The pairs between the same two bodies, slave to slave, in the job's order.
  std::vector<int> between;
  for (const int q : by_body.as_slave[static_cast<size_t>(pair.slave_body)])
    if (problem.contacts[static_cast<size_t>(q)].master_body == pair.master_body) between.push_back(q);
  std::set<std::string> slave_edges, master_edges;
  for (const int q : between) {
    slave_edges.insert(problem.contacts[static_cast<size_t>(q)].slave_edge);
    master_edges.insert(problem.contacts[static_cast<size_t>(q)].master_edge);
  }
  const auto s = chain(slave, connected(slave, pair.slave_edge, slave_edges));
  const auto m = chain(master, connected(master, pair.master_edge, master_edges));
  PairGroup g;
  if (!s || !m) {  // alone
    g.pairs = {pair_index};
    g.slave = *chain(slave, {pair.slave_edge});
    g.master = *chain(master, {pair.master_edge});
  } else {
    g.slave = *s;
    g.master = *m;
    for (const int q : between) {
      const ContactPair& c = problem.contacts[static_cast<size_t>(q)];
      if (g.slave.index(c.slave_edge) < g.slave.edges.size() && g.master.index(c.master_edge) < g.master.edges.size())
        g.pairs.push_back(q);
    }
  }
  g.by_edges.assign(g.slave.edges.size(), std::vector<int>(g.master.edges.size(), -1));
  for (int q : g.pairs) {
    const ContactPair& c = problem.contacts[static_cast<size_t>(q)];
    int& slot = g.by_edges[g.slave.index(c.slave_edge)][g.master.index(c.master_edge)];
    if (slot < 0) slot = q;
  }
  return g;
}

}  // namespace contact::mortar
