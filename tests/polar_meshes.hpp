// Polar meshes of a disk and of an annulus about the origin, for closed contact curves: nt nodes round every
// circle at the angles 2 pi j / nt (j = 0 on the positive x axis, counter-clockwise), so each mesh is unchanged by
// a rotation through 2 pi / nt and by the reflection in the x axis. A disk has a centre node, a fan of triangles
// round it and quadrilaterals outside; an annulus quadrilaterals only.
#pragma once

#include "contact/mesh.hpp"
#include "contact/problem.hpp"

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace contact::testing {

struct PolarMesh {
  mesh::Mesh mesh;
  std::vector<std::array<int, 2>> inner, outer;  // the sides of the inner circle (an annulus's) and the outer one
};

namespace polar_detail {
inline mesh::Point at(double r, int j, int nt) {
  const double t = 2 * 3.14159265358979323846 * j / nt;
  return {r * std::cos(t), r * std::sin(t)};
}
// The quadrilaterals between ring k (nodes first_k + j) and ring k + 1, and the circle's sides on a ring.
inline void quads(mesh::Mesh& m, int first_k, int first_k1, int nt) {
  for (int j = 0; j < nt; ++j) {
    const int jn = (j + 1) % nt;
    m.cells.push_back({first_k + j, first_k1 + j, first_k1 + jn, first_k + jn});
  }
}
inline std::vector<std::array<int, 2>> circle(int first, int nt) {
  std::vector<std::array<int, 2>> out;
  for (int j = 0; j < nt; ++j) out.push_back({first + j, first + (j + 1) % nt});
  return out;
}
}  // namespace polar_detail

// The disk r <= R: node 0 its centre, ring k = 1 .. nr at radius R k / nr (node 1 + (k - 1) nt + j). Vertices
// "centre" and "east" (R, 0); `outer` is the rim.
inline PolarMesh polar_disk(double R, int nr, int nt) {
  PolarMesh p;
  auto& m = p.mesh;
  m.nodes.push_back(mesh::Point(0, 0));
  for (int k = 1; k <= nr; ++k)
    for (int j = 0; j < nt; ++j) m.nodes.push_back(polar_detail::at(R * k / nr, j, nt));
  for (int j = 0; j < nt; ++j) m.cells.push_back({0, 1 + j, 1 + (j + 1) % nt});
  for (int k = 1; k < nr; ++k) polar_detail::quads(m, 1 + (k - 1) * nt, 1 + k * nt, nt);
  m.level.assign(m.cells.size(), 0);
  p.outer = polar_detail::circle(1 + (nr - 1) * nt, nt);
  m.vertices = {{"centre", 0}, {"east", 1 + (nr - 1) * nt}};
  return p;
}

// The annulus a <= r <= b: ring k = 0 .. nr at radius a + (b - a) k / nr (node k nt + j). Vertices "east",
// "north" and "west" on the outer circle (nt a multiple of 4).
inline PolarMesh polar_annulus(double a, double b, int nr, int nt) {
  PolarMesh p;
  auto& m = p.mesh;
  for (int k = 0; k <= nr; ++k)
    for (int j = 0; j < nt; ++j) m.nodes.push_back(polar_detail::at(a + (b - a) * k / nr, j, nt));
  for (int k = 0; k < nr; ++k) polar_detail::quads(m, k * nt, (k + 1) * nt, nt);
  m.level.assign(m.cells.size(), 0);
  p.inner = polar_detail::circle(0, nt);
  p.outer = polar_detail::circle(nr * nt, nt);
  m.vertices = {{"east", nr * nt}, {"north", nr * nt + nt / 4}, {"west", nr * nt + nt / 2}};
  return p;
}

// The shrink fit of api/examples/shrink_fit.json as a full 360-degree model on polar meshes: a solid steel shaft
// r <= a in a ring a .. b, radial interference delta as gap.constant = -delta, plane strain. Lame: a uniform
// pressure p = E' delta / (2 a) (1 - a^2 / b^2), E' = E / (1 - nu^2) (109.89). The closed contact curves are the
// shaft's "rim" and the ring's "bore". Both bodies are held only where the exact (radial) solution is already
// zero: the shaft at its centre and in y at (a, 0), the ring in y at (b, 0) and (-b, 0) and in x at (0, b); on
// meshes symmetric about the x axis the discrete solution is zero there too, so these supports carry nothing.
struct FullShrinkFit {
  double E = 2e5, nu = 0.3, a = 500.0, b = 1000.0, delta = 0.6667;
  int shaft_rings = 8, ring_rings = 16;

  double lame() const { return E / (1 - nu * nu) * delta / (2 * a) * (1 - a * a / (b * b)); }

  // shaft_nt and ring_nt nodes round the interface (equal: matching meshes); the ring's bore as the slave, or the
  // shaft's rim.
  Problem problem(int shaft_nt, int ring_nt, bool ring_slave) const {
    auto held = [](const std::string& vertex, bool x, bool y) {
      BoundaryCondition bc;
      bc.kind = BoundaryCondition::Kind::displacement;
      bc.vertex = vertex;
      if (x) bc.ux = 0.0;
      if (y) bc.uy = 0.0;
      return bc;
    };
    Problem p;
    p.name = "shrink_fit_full";
    p.model.plane = Plane::strain;
    PolarMesh shaft = polar_disk(a, shaft_rings, shaft_nt), ring = polar_annulus(a, b, ring_rings, ring_nt);
    if (mesh::add_edge_set(shaft.mesh, "rim", shaft.outer) || mesh::add_edge_set(ring.mesh, "bore", ring.inner) ||
        mesh::add_edge_set(ring.mesh, "outside", ring.outer))
      return {};
    Body s{"shaft", {E, nu}, std::move(shaft.mesh), {held("centre", true, true), held("east", false, true)}};
    Body r{"ring", {E, nu}, std::move(ring.mesh), {held("east", false, true), held("west", false, true), held("north", true, false)}};
    p.bodies = {std::move(s), std::move(r)};
    ContactPair c;
    c.slave_body = ring_slave ? 1 : 0;
    c.master_body = ring_slave ? 0 : 1;
    c.slave_edge = ring_slave ? "bore" : "rim";
    c.master_edge = ring_slave ? "rim" : "bore";
    c.name = ring_slave ? "ring.bore-shaft.rim" : "shaft.rim-ring.bore";
    c.gap.constant = -delta;
    p.contacts = {c};
    return p;
  }
};

}  // namespace contact::testing
