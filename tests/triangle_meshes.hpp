// Triangle and mixed meshes for the tests: a quadrilateral mesh with some or all of its cells split along a
// diagonal (alternating between the two diagonals, so that no direction is preferred). Edge sets and curves
// follow, so boundary conditions, contacts and refinement onto curves work as on the original mesh.
#pragma once

#include "contact/mesh.hpp"

#include <functional>

namespace contact::testing {

inline mesh::Mesh split_into_triangles(const mesh::Mesh& quads, const std::function<bool(int)>& split = {}) {
  mesh::Mesh m = quads;
  // side_to[c][s]: where side s of quadrilateral c went.
  std::vector<std::array<mesh::EdgeRef, 4>> side_to(quads.cells.size());
  for (int c = 0; c < quads.num_cells(); ++c) {
    auto& to = side_to[static_cast<size_t>(c)];
    const mesh::Cell q = quads.cells[static_cast<size_t>(c)];
    if (q.is_triangle() || (split && !split(c))) {
      for (int s = 0; s < q.size(); ++s) to[static_cast<size_t>(s)] = {c, s};
      continue;
    }
    const int other = m.num_cells();
    if (c % 2 == 0) {  // diagonal 0-2: (0, 1, 2) and (0, 2, 3)
      m.cells[static_cast<size_t>(c)] = {q[0], q[1], q[2]};
      m.cells.push_back({q[0], q[2], q[3]});
      to = {mesh::EdgeRef{c, 0}, mesh::EdgeRef{c, 1}, mesh::EdgeRef{other, 1}, mesh::EdgeRef{other, 2}};
    } else {  // diagonal 1-3: (0, 1, 3) and (1, 2, 3)
      m.cells[static_cast<size_t>(c)] = {q[0], q[1], q[3]};
      m.cells.push_back({q[1], q[2], q[3]});
      to = {mesh::EdgeRef{c, 0}, mesh::EdgeRef{other, 0}, mesh::EdgeRef{other, 1}, mesh::EdgeRef{c, 2}};
    }
    m.level.push_back(m.level[static_cast<size_t>(c)]);
  }
  for (auto& [name, refs] : m.edge_sets)
    for (auto& e : refs) e = side_to[static_cast<size_t>(e.cell)][static_cast<size_t>(e.side)];
  return m;
}

}  // namespace contact::testing
