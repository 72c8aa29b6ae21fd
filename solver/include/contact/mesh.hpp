// Meshes of one body: quadrilaterals and triangles (mixed meshes allowed), plain arrays plus named boundary edge
// sets.
//
// Layering: this module knows nothing of finite elements or contact. A Mesh is a value type; copies are
// independent. Node coordinates are in the user's length unit.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace contact::mesh {

using Point = Eigen::Vector2d;

// One cell: a triangle (3 nodes) or a quadrilateral (4 nodes), counter-clockwise. Iterating a cell visits its
// nodes only (3 or 4); cell[k] is local node k.
class Cell {
 public:
  using value_type = int;
  using iterator = int*;
  using const_iterator = const int*;

  Cell() = default;
  Cell(int a, int b, int c) : nodes_{a, b, c, -1}, size_(3) {}
  Cell(int a, int b, int c, int d) : nodes_{a, b, c, d}, size_(4) {}

  int size() const { return size_; }  // the number of nodes, which is also the number of sides
  bool is_triangle() const { return size_ == 3; }
  int& operator[](size_t k) { return nodes_[k]; }
  int operator[](size_t k) const { return nodes_[k]; }
  int* begin() { return nodes_.data(); }
  int* end() { return nodes_.data() + size_; }
  const int* begin() const { return nodes_.data(); }
  const int* end() const { return nodes_.data() + size_; }
  bool operator==(const Cell& o) const { return size_ == o.size_ && std::equal(begin(), end(), o.begin()); }
  bool operator!=(const Cell& o) const { return !(*this == o); }

 private:
  std::array<int, 4> nodes_{{-1, -1, -1, -1}};
  int size_ = 0;
};

// One side of a cell: side s joins the cell's local nodes s and (s + 1) % n (n = 3 or 4), so with
// counter-clockwise cells the body lies to the left of the side's direction and its outward normal points to the
// right.
struct EdgeRef {
  int cell = -1;
  int side = -1;
  bool operator==(const EdgeRef& o) const { return cell == o.cell && side == o.side; }
};

// The true geometry of a block edge, so that refinement can put new boundary nodes on the curve, not on the
// chord. A straight edge needs no curve.
struct Curve {
  enum class Kind { line, parabola, arc };
  Kind kind = Kind::line;
  // parabola: the graph y(x) = a x^2 + b x + c through the edge's two end corners (b, c follow from them).
  double a = 0.0, b = 0.0, c = 0.0;
  // arc: circle of this centre and radius, the shorter arc between the end corners.
  Point center = Point::Zero();
  double radius = 0.0;

  // The point of the curve between p and q (both on the curve) at parameter t in [0, 1]: for a parabola
  // t runs linearly in x, for an arc linearly in angle, for a line along the chord.
  Point between(const Point& p, const Point& q, double t) const;
};

struct Mesh {
  std::vector<Point> nodes;
  std::vector<Cell> cells;  // node indices, counter-clockwise
  std::vector<int> level;   // refinement level per cell (0 = initial mesh)
  // Boundary edge sets by name, each ordered along the edge (consecutive entries share a node), counter-clockwise
  // along the boundary (the body on the left). An edge set is an open chain (two ends) or a closed loop (the last
  // side ends where the first begins: a bore, a shaft's rim, the whole outline of a body); see edge_set_closed().
  std::map<std::string, std::vector<EdgeRef>> edge_sets;
  // True geometry of named edges that are curved (block edges); absent means straight.
  std::map<std::string, Curve> edge_curves;
  // True geometry of single boundary sides, by (smaller node, larger node): the arcs of a Gmsh mesh's curves.
  // Refinement puts a split side's midpoint on its curve and passes the curve on to the two halves.
  std::map<std::pair<int, int>, Curve> side_curves;
  // Named vertices (point loads and point supports): a block's corners are "bottom_left" (corner 0),
  // "bottom_right" (1), "top_right" (2) and "top_left" (3). Refinement keeps node indices, so these stay valid.
  std::map<std::string, int> vertices;
  // Edges split by refinement: (smaller node, larger node) -> midpoint node. A cell side (a, b) whose edge is
  // split carries a hanging node (the neighbour across it is refined); see hanging_nodes().
  std::map<std::pair<int, int>, int> edge_midpoint;

  int num_nodes() const { return static_cast<int>(nodes.size()); }
  int num_cells() const { return static_cast<int>(cells.size()); }
  // True when some cell is a triangle (false for an all-quadrilateral mesh).
  bool has_triangles() const;
  // The two node indices of a side, in the cell's counter-clockwise direction.
  std::array<int, 2> edge_nodes(EdgeRef e) const {
    const auto& c = cells[static_cast<size_t>(e.cell)];
    return {c[static_cast<size_t>(e.side)], c[static_cast<size_t>((e.side + 1) % c.size())]};
  }
  // Nodes of an edge set in order along the set: n_edges + 1 nodes for an open chain, n_edges for a closed loop
  // (each node once, from the loop's start: the first node of its first side; the side from the last node back
  // to the first closes it). Empty if unknown.
  std::vector<int> edge_set_nodes(const std::string& name) const;
  // Whether an edge set is a closed loop: its last side ends at its first side's first node. Derived from the
  // sides themselves, so refinement (which splits every side in place, in order) keeps it.
  bool edge_set_closed(const std::string& name) const;
  // Area of a cell (shoelace formula; positive for counter-clockwise cells).
  double cell_area(int cell) const;
  Eigen::Vector2d bbox_min() const;
  Eigen::Vector2d bbox_max() const;
};

// ---------------------------------------------------------------------------------------------------------
// Block generator: one quadrilateral patch mapped by transfinite interpolation from its four (possibly
// curved) edges. Corners are counter-clockwise; edges are bottom (corner 0 -> 1), right (1 -> 2),
// top (3 -> 2 in parameter direction, i.e. traversed 2 -> 3 along the boundary), left (0 -> 3 likewise).
struct BlockSpec {
  std::array<Point, 4> corners;
  int nx = 1, ny = 1;
  // Optional curves per edge name ("bottom", "right", "top", "left").
  std::map<std::string, Curve> curves;
  // Grading: ratio of the largest to the smallest element size across the block, smallest at the named edge.
  // Keys "bottom" or "top" grade in y (the eta direction), "left" or "right" in x (xi); at most one per direction.
  std::map<std::string, double> grading;
};

// Builds the block mesh with edge sets "bottom", "right", "top", "left" (each ordered counter-clockwise along
// the boundary) and the four corners as named vertices. Assumes the spec was validated (nx, ny >= 1, ratios > 0,
// corners on their curves).
Mesh make_block(const BlockSpec& spec);

// Completes a parabola or arc Curve for the edge from p to q: for a parabola, fills b and c from a; returns
// an error message if the ends do not fit the curve (equal x for a parabola, not on the circle for an arc).
std::optional<std::string> fit_curve(Curve& curve, const Point& p, const Point& q);

// Adds a named edge set from node pairs (either orientation) of an explicit mesh: each pair must be a
// boundary side of exactly one cell, and the pairs must form one connected piece along the boundary: one open
// chain, or one closed loop (around the body or a hole). A set of several pieces has no one order: it is an error.
// The set is stored in chain order, counter-clockwise along the boundary (the body on the left); an open chain
// from its one end, a closed loop from the first node (counter-clockwise) of the side given first, `pairs[0]`.
// Returns an error message naming the offending pair (by its index in `pairs`), or saying why the set is not one
// piece.
std::optional<std::string> add_edge_set(Mesh& m, const std::string& name, const std::vector<std::array<int, 2>>& pairs);

// ---------------------------------------------------------------------------------------------------------
// Refinement (quadtree): a marked cell splits into four (a quadrilateral by its side midpoints and its centre, a
// triangle by its side midpoints); the mesh is kept 1-irregular (at most one hanging node per side) by also
// refining coarser neighbours where needed, across quadrilaterals and triangles alike. New nodes on a curved named
// edge lie on its curve.

// Rule for a node created by refinement: its value of the finite-element field (bilinear on a quadrilateral,
// linear on a triangle) is sum weight * value(parent node).
struct NewNode {
  int node = -1;
  std::vector<std::pair<int, double>> parents;
};

struct RefinementResult {
  std::vector<NewNode> new_nodes;  // in creation order (parents precede children)
  int refined_cells = 0;           // cells split, including those added to keep the mesh 1-irregular
  int closure_cells = 0;           // of which added for 1-irregularity
};

// Refines the marked cells (indices into m.cells; refined cells keep their index for the first child, the other
// three children are appended). Cells at max_level are not refined (they are skipped). Edge sets follow.
RefinementResult refine(Mesh& m, const std::vector<int>& marked, int max_level = 1 << 20);

// Every cell once.
RefinementResult refine_uniform(Mesh& m);

// Hanging nodes of the current mesh: node -> the two end nodes of the cell side it hangs on (its value is the
// mean of theirs: Q1 and P1 are linear along a side).
std::map<int, std::pair<int, int>> hanging_nodes(const Mesh& m);

// Values of a nodal field (rows = nodes) extended to the nodes created by a refinement.
Eigen::MatrixXd transfer(const Eigen::MatrixXd& old_values, const RefinementResult& refinement, int new_node_count);

// Mesh sanity checks used by validation. Each problem is a message naming the cell or edge.
std::vector<std::string> check_cells(const Mesh& m);

// The pieces of a mesh (cells joined through shared sides are in one piece): each cell's piece, numbered from 0
// in the order of their first cells, so a mesh in one piece has all zeros.
std::vector<int> pieces(const Mesh& m);

}  // namespace contact::mesh
