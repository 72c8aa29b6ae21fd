// Quadtree refinement with hanging nodes (deal.II / MFEM style): see mesh.hpp.
#include "contact/mesh.hpp"

#include <algorithm>
#include <array>
#include <set>

namespace contact::mesh {

namespace {

std::pair<int, int> key(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

// Which named edge set, if any, holds each boundary side (for putting midpoints on curves).
std::map<std::pair<int, int>, std::string> boundary_side_names(const Mesh& m) {
  std::map<std::pair<int, int>, std::string> out;
  for (const auto& [name, refs] : m.edge_sets)
    for (const auto& e : refs) {
      const auto n = m.edge_nodes(e);
      out[key(n[0], n[1])] = name;
    }
  return out;
}

// Active cells by side: side key -> cells having it.
std::map<std::pair<int, int>, std::vector<int>> sides_of(const Mesh& m) {
  std::map<std::pair<int, int>, std::vector<int>> out;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      out[key(n[0], n[1])].push_back(c);
    }
  return out;
}

// The marked cells below max_level, closed: refining a cell whose side is half of a coarser neighbour's side
// would put two hanging nodes on that neighbour's side, so the neighbour is refined too (and so on). Counts the
// cells the closure added in `closure_cells`.
std::vector<char> mark_with_closure(const Mesh& m, const std::vector<int>& marked_in, int max_level,
                                    int& closure_cells) {
  std::vector<char> marked(static_cast<size_t>(m.num_cells()), 0);
  for (int c : marked_in)
    if (c >= 0 && c < m.num_cells() && m.level[static_cast<size_t>(c)] < max_level) marked[static_cast<size_t>(c)] = 1;
  std::map<int, std::pair<int, int>> parent_edge;  // midpoint -> split edge
  for (const auto& [edge, mid] : m.edge_midpoint) parent_edge[mid] = edge;
  const auto sides = sides_of(m);
  std::vector<int> queue;
  for (int c = 0; c < m.num_cells(); ++c)
    if (marked[static_cast<size_t>(c)]) queue.push_back(c);
  while (!queue.empty()) {
    const int c = queue.back();
    queue.pop_back();
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      for (int end = 0; end < 2; ++end) {
        auto pe = parent_edge.find(n[static_cast<size_t>(end)]);
        if (pe == parent_edge.end()) continue;
        const int other = n[static_cast<size_t>(1 - end)];
        if (pe->second.first != other && pe->second.second != other) continue;
        // (n0, n1) is half of the split edge pe->second; a coarser active cell with that whole side?
        auto coarse = sides.find(pe->second);
        if (coarse == sides.end()) continue;
        for (int nb : coarse->second)
          if (!marked[static_cast<size_t>(nb)]) {
            marked[static_cast<size_t>(nb)] = 1;
            ++closure_cells;
            queue.push_back(nb);
          }
      }
    }
  }
  return marked;
}

// Splits cells of one mesh into four, adding the nodes (side midpoints, on the true curve where the side lies on
// one; quad centres) and recording each new node's parents in the result.
class CellSplitter {
 public:
  CellSplitter(Mesh& m, RefinementResult& result) : m_(m), result_(result), names_(boundary_side_names(m)) {}

  // Child k of a refined cell holds its corner k at local node k (the fourth child of a triangle is the middle
  // one), so side s of the parent is side s of children s and (s + 1) % n. The first child keeps the parent's
  // index; the others are appended. Returns the children's indices.
  std::array<int, 4> split(int c) {
    const Cell q = m_.cells[static_cast<size_t>(c)];
    const int level = m_.level[static_cast<size_t>(c)] + 1;
    std::vector<Cell> split;
    if (q.is_triangle()) {
      const int m01 = midpoint(q[0], q[1]), m12 = midpoint(q[1], q[2]), m20 = midpoint(q[2], q[0]);
      split = {{q[0], m01, m20}, {m01, q[1], m12}, {m20, m12, q[2]}, {m01, m12, m20}};
    } else {
      const int m01 = midpoint(q[0], q[1]), m12 = midpoint(q[1], q[2]), m23 = midpoint(q[2], q[3]),
                m30 = midpoint(q[3], q[0]);
      // Centre: the bilinear centre corrected for curved sides (equal to the corner mean for straight ones).
      const auto& x = m_.nodes;
      const Point centre = 0.5 * (x[static_cast<size_t>(m01)] + x[static_cast<size_t>(m12)] +
                                  x[static_cast<size_t>(m23)] + x[static_cast<size_t>(m30)]) -
                           0.25 * (x[static_cast<size_t>(q[0])] + x[static_cast<size_t>(q[1])] +
                                   x[static_cast<size_t>(q[2])] + x[static_cast<size_t>(q[3])]);
      const int ctr = add_node(centre, {{q[0], 0.25}, {q[1], 0.25}, {q[2], 0.25}, {q[3], 0.25}});
      split = {{q[0], m01, ctr, m30}, {m01, q[1], m12, ctr}, {ctr, m12, q[2], m23}, {m30, ctr, m23, q[3]}};
    }
    std::array<int, 4> children{c, -1, -1, -1};
    m_.cells[static_cast<size_t>(c)] = split[0];
    m_.level[static_cast<size_t>(c)] = level;
    for (size_t k = 1; k < 4; ++k) {
      children[k] = m_.num_cells();
      m_.cells.push_back(split[k]);
      m_.level.push_back(level);
    }
    ++result_.refined_cells;
    return children;
  }

 private:
  int add_node(const Point& x, std::vector<std::pair<int, double>> parents) {
    const int id = m_.num_nodes();
    m_.nodes.push_back(x);
    result_.new_nodes.push_back({id, std::move(parents)});
    return id;
  }

  // The midpoint of side (a, b): the existing one if a neighbour split it, else a new node.
  int midpoint(int a, int b) {
    auto it = m_.edge_midpoint.find(key(a, b));
    if (it != m_.edge_midpoint.end()) return it->second;
    const Point& pa = m_.nodes[static_cast<size_t>(a)];
    const Point& pb = m_.nodes[static_cast<size_t>(b)];
    Point x = 0.5 * (pa + pb);
    auto named = names_.find(key(a, b));
    if (named != names_.end()) {
      auto curve = m_.edge_curves.find(named->second);
      if (curve != m_.edge_curves.end()) x = curve->second.between(pa, pb, 0.5);  // on the true curve
    }
    auto side = m_.side_curves.find(key(a, b));
    if (side != m_.side_curves.end()) x = side->second.between(pa, pb, 0.5);
    const int id = add_node(x, {{a, 0.5}, {b, 0.5}});
    m_.edge_midpoint[key(a, b)] = id;
    if (side != m_.side_curves.end()) {  // the halves lie on the same curve
      const Curve curve = side->second;
      m_.side_curves.erase(side);
      m_.side_curves[key(a, id)] = curve;
      m_.side_curves[key(id, b)] = curve;
    }
    return id;
  }

  Mesh& m_;
  RefinementResult& result_;
  const std::map<std::pair<int, int>, std::string> names_;
};

// Every named edge set's refined sides become the two children's sides (cells before the split: n_before).
void split_edge_sets(Mesh& m, const std::vector<std::array<int, 4>>& children, int n_before) {
  for (auto& [name, refs] : m.edge_sets) {
    std::vector<EdgeRef> out;
    out.reserve(refs.size() * 2);
    for (const auto& e : refs) {
      if (e.cell >= n_before || children[static_cast<size_t>(e.cell)][0] < 0) {
        out.push_back(e);
        continue;
      }
      const auto& ch = children[static_cast<size_t>(e.cell)];
      const int n_sides = m.cells[static_cast<size_t>(e.cell)].size();
      out.push_back({ch[static_cast<size_t>(e.side)], e.side});
      out.push_back({ch[static_cast<size_t>((e.side + 1) % n_sides)], e.side});
    }
    refs = std::move(out);
  }
}

// Split edges no longer carry a hanging node once both sides are refined; keep the map only for sides that are
// still active on some cell (it is also how the next refinement finds coarser neighbours).
void forget_inactive_midpoints(Mesh& m) {
  std::set<std::pair<int, int>> active;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      active.insert(key(n[0], n[1]));
    }
  for (auto it = m.edge_midpoint.begin(); it != m.edge_midpoint.end();) {
    if (!active.count(it->first))
      it = m.edge_midpoint.erase(it);
    else
      ++it;
  }
}

}  // namespace

std::map<int, std::pair<int, int>> hanging_nodes(const Mesh& m) {
  std::map<int, std::pair<int, int>> out;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto n = m.edge_nodes({c, s});
      auto it = m.edge_midpoint.find(key(n[0], n[1]));
      // The side is active on this (coarser) cell but split on the other side: its midpoint hangs.
      if (it != m.edge_midpoint.end()) out[it->second] = {n[0], n[1]};
    }
  return out;
}

RefinementResult refine(Mesh& m, const std::vector<int>& marked_in, int max_level) {
  RefinementResult result;
  const std::vector<char> marked = mark_with_closure(m, marked_in, max_level, result.closure_cells);
  CellSplitter splitter(m, result);
  const int n_before = m.num_cells();
  std::vector<std::array<int, 4>> children(static_cast<size_t>(n_before), {-1, -1, -1, -1});
  for (int c = 0; c < n_before; ++c)
    if (marked[static_cast<size_t>(c)]) children[static_cast<size_t>(c)] = splitter.split(c);
  split_edge_sets(m, children, n_before);
  forget_inactive_midpoints(m);
  return result;
}

RefinementResult refine_uniform(Mesh& m) {
  std::vector<int> all(static_cast<size_t>(m.num_cells()));
  for (int c = 0; c < m.num_cells(); ++c) all[static_cast<size_t>(c)] = c;
  return refine(m, all);
}

Eigen::MatrixXd transfer(const Eigen::MatrixXd& old_values, const RefinementResult& refinement, int new_node_count) {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(new_node_count, old_values.cols());
  out.topRows(old_values.rows()) = old_values;
  for (const auto& nn : refinement.new_nodes)
    for (const auto& [parent, w] : nn.parents) out.row(nn.node) += w * out.row(parent);
  return out;
}

}  // namespace contact::mesh
