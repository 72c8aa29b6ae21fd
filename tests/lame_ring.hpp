// The Lame ring, an exact solution for convergence tests: the quarter of a thick ring a <= r <= b under internal
// pressure P, plane strain, symmetry on both straight edges. u_r = A r + B / r with
// A = (1+nu)(1-2nu) P a^2 / (E (b^2 - a^2)), B = (1+nu) P a^2 b^2 / (E (b^2 - a^2)).
#pragma once

#include "contact/mesh.hpp"
#include "contact/problem.hpp"

namespace contact::testing {

struct LameRing {
  double E = 1000.0, nu = 0.3, P = 1.0, a = 1.0, b = 2.0;

  double A() const { return (1 + nu) * (1 - 2 * nu) * P * a * a / (E * (b * b - a * a)); }
  double B() const { return (1 + nu) * P * a * a * b * b / (E * (b * b - a * a)); }
  // The largest displacement (at r = a), for relative errors.
  double scale() const { return A() * a + B() / a; }
  Eigen::Vector2d exact(const Eigen::Vector2d& x) const {
    const double r = x.norm();
    return (A() * r + B() / r) * x / r;
  }

  // The quarter ring as a block: bottom on y = 0, top on x = 0, left the inner arc, right the outer one.
  mesh::Mesh block(int nx, int ny) const {
    mesh::BlockSpec s;
    s.corners = {mesh::Point(a, 0), mesh::Point(b, 0), mesh::Point(0, b), mesh::Point(0, a)};
    s.nx = nx;
    s.ny = ny;
    mesh::Curve outer, inner;
    outer.kind = inner.kind = mesh::Curve::Kind::arc;
    outer.radius = b;
    inner.radius = a;
    mesh::fit_curve(outer, s.corners[1], s.corners[2]);
    mesh::fit_curve(inner, s.corners[0], s.corners[3]);
    s.curves["right"] = outer;
    s.curves["left"] = inner;
    return mesh::make_block(s);
  }

  // The body on `mesh` (edges named as block() names them): symmetry supports and the inner pressure.
  Body body(mesh::Mesh mesh) const {
    Body body;
    body.name = "ring";
    body.material = {E, nu};
    body.mesh = std::move(mesh);
    BoundaryCondition sym_x{"bottom", BoundaryCondition::Kind::displacement};  // y = 0 line: u_y = 0
    sym_x.uy = 0.0;
    BoundaryCondition sym_y{"top", BoundaryCondition::Kind::displacement};     // x = 0 line: u_x = 0
    sym_y.ux = 0.0;
    BoundaryCondition pressure{"left", BoundaryCondition::Kind::traction};     // inner arc
    pressure.normal_pressure = true;
    pressure.pressure = P;
    body.boundary = {sym_x, sym_y, pressure};
    return body;
  }
};

}  // namespace contact::testing
