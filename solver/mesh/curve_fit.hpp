// A smooth description of a curve known only by its nodes (docs/algorithm.md, "Contact geometry on curves"):
// where a Gmsh curve is neither straight nor a circle (a spline, an ellipse), and on an explicit mesh's edges unless
// the job says otherwise, each side gets the arc through its two nodes whose curvature is the mean of the circles
// through its node triples (k - 1, k, k + 1) and (k, k + 1, k + 2) (at a piece's ends the one triple there). Two
// meshes of one curve then see nearly the same curve: the arc's distance from the true curve falls as h^3 (the
// chord's as h^2: its sag h^2 kappa / 8), measured on an ellipse in tests/unit/test_edge_curves.cpp. A straight stretch
// (a sag below 1e-7 of the side) keeps its chord, so flat edges compute exactly what they did.
//
// Corners: a chain of nodes may turn sharply where the body has a corner (an explicit edge round two sides of a
// punch). A node is a corner where the chain turns by more than 45 degrees, or by more than 5 degrees and three
// times as much as at each neighbour that has a turn (on a mesh of a smooth curve neighbouring turns differ by the
// ratio of neighbouring side lengths, at most about 2 on a graded mesh). The chain is fitted piecewise between its
// corners, so no arc rounds a corner off.
#pragma once

#include "contact/mesh.hpp"

#include <optional>
#include <string>
#include <vector>

namespace contact::mesh {

// Per side of the chain of `nodes` (side k from node k to k + 1; on a closed chain the last side from the last
// node back to the first), its fitted arc, or nullopt where the chain is locally straight.
std::vector<std::optional<Curve>> fitted_arcs(const std::vector<Point>& nodes, bool closed);

// Which nodes of the chain are corners (the rule above); an open chain's ends are not.
std::vector<bool> chain_corners(const std::vector<Point>& nodes, bool closed);

// The fitted arcs of a named edge's sides as their side curves (Mesh::side_curves), where the side has none and the
// edge no edge curve. An edge the mesh does not have is left alone.
void fit_edge_curves(Mesh& m, const std::string& edge);

// A curve the job gives for a named edge, set on each of its sides (an arc's centre and radius, a parabola's a;
// fit_curve checks each side's ends on it): the side that is not on it, or nullopt.
std::optional<std::string> set_edge_curve(Mesh& m, const std::string& edge, const Curve& curve);

}  // namespace contact::mesh
