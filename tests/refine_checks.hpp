// Helpers shared by the refinement tests (test_refine.cpp on quadrilaterals, test_triangles.cpp on triangle and
// mixed meshes): a local refinement towards a point, and the 1-irregularity check.
#pragma once

#include "contact/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace contact::testing {

// Refines the cells whose bounding box holds p, `times` times (a local refinement towards p). Returns the number
// of cells the 1-irregularity closure added.
inline int refine_towards(mesh::Mesh& m, const mesh::Point& p, int times) {
  int closure = 0;
  for (int t = 0; t < times; ++t) {
    std::vector<int> marked;
    for (int c = 0; c < m.num_cells(); ++c) {
      Eigen::Vector2d lo = m.nodes[static_cast<size_t>(m.cells[static_cast<size_t>(c)][0])], hi = lo;
      for (int k : m.cells[static_cast<size_t>(c)]) {
        lo = lo.cwiseMin(m.nodes[static_cast<size_t>(k)]);
        hi = hi.cwiseMax(m.nodes[static_cast<size_t>(k)]);
      }
      if ((p.array() >= lo.array() - 1e-12).all() && (p.array() <= hi.array() + 1e-12).all()) marked.push_back(c);
    }
    closure += mesh::refine(m, marked).closure_cells;
  }
  return closure;
}

// The most nodes strictly inside one side of an active cell (1 = at most one hanging node per side).
inline int max_nodes_inside_a_side(const mesh::Mesh& m) {
  int worst = 0;
  for (int c = 0; c < m.num_cells(); ++c)
    for (int s = 0; s < m.cells[static_cast<size_t>(c)].size(); ++s) {
      const auto e = m.edge_nodes({c, s});
      const Eigen::Vector2d a = m.nodes[static_cast<size_t>(e[0])], b = m.nodes[static_cast<size_t>(e[1])];
      int inside = 0;
      for (const auto& x : m.nodes) {
        const double t = (x - a).dot(b - a) / (b - a).squaredNorm();
        const double off = std::abs((x - a).x() * (b - a).y() - (x - a).y() * (b - a).x()) / (b - a).norm();
        if (t > 1e-9 && t < 1 - 1e-9 && off < 1e-9) ++inside;
      }
      worst = std::max(worst, inside);
    }
  return worst;
}

}  // namespace contact::testing
