// A smooth description of a curve known only by its nodes (docs/algorithm.md, "Contact geometry on curves"):
// where a Gmsh curve is neither straight nor a circle (a spline, an ellipse), each side gets the arc through its two
// nodes whose curvature is the mean of the circles through its node triples (k - 1, k, k + 1) and
// (k, k + 1, k + 2) (at an open chain's ends the one triple there). Two meshes of one curve then see nearly the
// same curve: the arc's distance from the true curve falls as h^3 (the chord's as h^2: its sag h^2 kappa / 8),
// measured on an ellipse in tests/test_edge_curves.cpp. A straight stretch (a sag below 1e-7 of the side) keeps
// its chord.
#pragma once

#include "contact/mesh.hpp"

#include <optional>
#include <vector>

namespace contact::mesh {

// Per side of the chain of `nodes` (side k from node k to k + 1; on a closed chain the last side from the last
// node back to the first), its fitted arc, or nullopt where the chain is locally straight.
std::vector<std::optional<Curve>> fitted_arcs(const std::vector<Point>& nodes, bool closed);

}  // namespace contact::mesh
