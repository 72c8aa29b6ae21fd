// The true shape of a contact edge, where the mesh knows it (docs/algorithm.md, "Contact geometry on curves").
//
// The mortar segment mesh (segments.hpp) cuts and pairs the two sides' chords: the displacement fields live on
// them. The gap and the normals are geometry, and where the job says what curve an edge's nodes lie on (a block's
// arc or parabola edge, mesh::Mesh::edge_curves; a Gmsh curve whose nodes lie on one circle, mesh::Mesh::side_curves)
// they are measured on that curve instead: a chord point x stands for the curve's point X opposite it (the radial
// projection onto an arc, the vertical one onto a parabola y(x)), the normal is the curve's there, and the gap is
// the distance along it to the master's curve. Two discretisations of one circle then see the same circle, however
// each cuts it, instead of two polygons whose sags h^2 / (8 R) differ.
//
// Where the mesh knows only the nodes (an explicit mesh's edges, a Gmsh spline), mesh/curve_fit.hpp gives the
// sides fitted arcs as their side curves. A segment without a curve (a straight edge, an explicit edge given
// "chords", a mesh built in code) keeps its chord, and the pair takes exactly the chord-based arithmetic there
// (pair.cpp).
#pragma once

#include "contact/mesh.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace contact::mortar {

class EdgeCurves {
 public:
  struct Frame {
    Eigen::Vector2d point = Eigen::Vector2d::Zero();   // on the curve (on the chord where there is none)
    Eigen::Vector2d normal = Eigen::Vector2d::Zero();  // outward unit normal there
  };

  EdgeCurves() = default;
  // The polyline's points and, per segment (points k -> k + 1), the curve it lies on; nullopt (or a line) for a
  // chord.
  EdgeCurves(std::vector<Eigen::Vector2d> points, std::vector<std::optional<mesh::Curve>> curves);

  // The curves of a polyline of mesh nodes, segment k on the edge edges[k]: a side's own curve (side_curves)
  // first, else its named edge's (edge_curves).
  static EdgeCurves of_sides(const mesh::Mesh& mesh, const std::vector<int>& polyline,
                             const std::vector<std::string>& edges);
  // The same, every segment on one edge.
  static EdgeCurves of_edge(const mesh::Mesh& mesh, const std::string& edge, const std::vector<int>& polyline) {
    return of_sides(mesh, polyline, std::vector<std::string>(polyline.size() < 2 ? 0 : polyline.size() - 1, edge));
  }

  size_t segments() const { return curves_.size(); }
  // Whether segment k has a curve other than its chord.
  bool curved(size_t k) const { return k < curves_.size() && curves_[k].has_value(); }
  bool any_curved() const;
  // The curve's point opposite the chord point at parameter xi of segment k, and its outward normal there.
  Frame at(size_t k, double xi) const;
  // The signed distance t along the unit direction n from x to segment k's curve (its chord where straight): the
  // root of smallest |t|, the curve continued past the segment's ends; nullopt when the line misses it.
  std::optional<double> hit(size_t k, const Eigen::Vector2d& x, const Eigen::Vector2d& n) const;
  // Where x + t n falls along segment k's chord (0 and 1 at its ends): which segment's stretch a hit lies on.
  double chord_parameter(size_t k, const Eigen::Vector2d& p) const;

 private:
  std::vector<Eigen::Vector2d> points_;
  std::vector<std::optional<mesh::Curve>> curves_;
};

}  // namespace contact::mortar
