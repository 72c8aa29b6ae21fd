// Boundary-element test problems with exact solutions, shared by tests/unit/test_bem.cpp (the dense BEM),
// tests/unit/test_hbem.cpp (the hierarchical one against the dense) and bench/bench_hbem.cpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "bem/bem.hpp"
#include "bem/kelvin.hpp"

namespace contact::bem::test_problems {

using Eigen::Matrix2d;
using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kPi = 3.14159265358979323846;
inline const Material kSteel{2.1e5, 0.3, true};

// An exact displacement field of the Navier equations without body force: u(x) and its gradient.
struct Field {
  std::function<Vector2d(const Vector2d&)> displacement;
  std::function<Matrix2d(const Vector2d&)> gradient;
  ElasticConstants constants;
  Vector3d stress(const Vector2d& x) const { return hooke_stress(constants, gradient(x)); }
  Vector2d traction(const Vector2d& x, const Vector2d& n) const {
    const Vector3d s = stress(x);
    return {s(0) * n.x() + s(2) * n.y(), s(2) * n.x() + s(1) * n.y()};
  }
};

// u = a + G x: a constant stress state with a rigid rotation in it.
inline Field linear_field(const Material& material) {
  Matrix2d g;
  g << 1.0e-3, 4.0e-4, -2.0e-4, -6.0e-4;
  const Vector2d a(2e-3, -1e-3);
  return {[a, g](const Vector2d& x) { return Vector2d(a + g * x); }, [g](const Vector2d&) { return g; },
          effective_constants(material)};
}

// The quadratic field u_x = s (a x^2 + b xy + c y^2), u_y = s (d x^2 + e xy + f y^2). Navier's equations
// mu lap(u) + (lambda + mu) grad(div u) = 0 read, for its constant second derivatives,
//   x: 2 mu (a + c) + (lambda + mu)(2a + e) = 0,   y: 2 mu (d + f) + (lambda + mu)(b + 2f) = 0,
// so with a = 1, b = 0.7, e = 0.5, f = -0.4 and rho = (lambda + mu) / mu:
//   c = -a - rho (2a + e) / 2,   d = -f - rho (b + 2f) / 2.
// The field depends on lambda / mu, so it tells plane strain from plane stress.
inline Field quadratic_field(const Material& material) {
  const ElasticConstants k = effective_constants(material);
  const double rho = (k.lame_lambda() + k.shear_modulus) / k.shear_modulus;
  const double a = 1.0, b = 0.7, e = 0.5, f = -0.4, s = 1e-3;
  const double c = -a - rho * (2 * a + e) / 2, d = -f - rho * (b + 2 * f) / 2;
  return {[=](const Vector2d& x) {
            return Vector2d(s * (a * x.x() * x.x() + b * x.x() * x.y() + c * x.y() * x.y()),
                            s * (d * x.x() * x.x() + e * x.x() * x.y() + f * x.y() * x.y()));
          },
          [=](const Vector2d& x) {
            Matrix2d g;
            g << 2 * a * x.x() + b * x.y(), b * x.x() + 2 * c * x.y(), 2 * d * x.x() + e * x.y(),
                e * x.x() + 2 * f * x.y();
            return Matrix2d(s * g);
          },
          k};
}

// Boundary condition of one side of a polygon, per component: true = displacement prescribed.
using SideCondition = std::array<bool, 2>;
constexpr SideCondition kDisplacement{true, true}, kTraction{false, false};
constexpr SideCondition kRollerX{false, true};  // u_y and t_x prescribed
constexpr SideCondition kRollerY{true, false};  // u_x and t_y prescribed

// The polygon `corners` (counter-clockwise) with each side split into elements no longer than h, and the exact
// data of `field` on it: prescribed displacements = nodal values, prescribed tractions = sigma n at the ends.
inline BoundaryProblem polygon_problem(const std::vector<Vector2d>& corners, const std::vector<SideCondition>& sides, double h,
                                const Field& field, const Material& material) {
  BoundaryProblem problem;
  problem.material = material;
  std::vector<std::size_t> side_of_element;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const Vector2d a = corners[k], b = corners[(k + 1) % corners.size()];
    const int m = static_cast<int>(std::ceil((b - a).norm() / h - 1e-9));
    for (int j = 0; j < m; ++j) {
      problem.nodes.push_back(a + (b - a) * (static_cast<double>(j) / m));
      side_of_element.push_back(k);
    }
  }
  const std::size_t n = problem.nodes.size();
  for (std::size_t e = 0; e < n; ++e) {
    const Vector2d x0 = problem.nodes[e], x1 = problem.nodes[(e + 1) % n];
    const Vector2d t = (x1 - x0).normalized(), normal(t.y(), -t.x());
    ElementData data;
    data.displacement_prescribed = sides[side_of_element[e]];
    for (int c = 0; c < 2; ++c) {
      const bool u = data.displacement_prescribed[static_cast<std::size_t>(c)];
      data.value(c, 0) = u ? field.displacement(x0)(c) : field.traction(x0, normal)(c);
      data.value(c, 1) = u ? field.displacement(x1)(c) : field.traction(x1, normal)(c);
    }
    problem.elements.push_back(data);
  }
  return problem;
}

inline const std::vector<Vector2d> kSquare{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
// Non-convex: the unit square without its upper right quarter; re-entrant corner at (0.5, 0.5).
inline const std::vector<Vector2d> kLShape{{0, 0}, {1, 0}, {1, 0.5}, {0.5, 0.5}, {0.5, 1}, {0, 1}};

// Lame: a thick ring a <= r <= b under internal pressure p. sigma_rr = A - B / r^2, sigma_tt = A + B / r^2,
// A = p a^2 / (b^2 - a^2), B = p a^2 b^2 / (b^2 - a^2); plane strain u_r = (1 + nu) / E ((1 - 2 nu) A r + B / r).
struct Lame {
  double a = 1.0, b = 2.0, p = 100.0;
  double A() const { return p * a * a / (b * b - a * a); }
  double B() const { return p * a * a * b * b / (b * b - a * a); }
  Vector3d stress(const Vector2d& x) const {
    const double r2 = x.squaredNorm(), c = x.x() / std::sqrt(r2), s = x.y() / std::sqrt(r2);
    const double rr = A() - B() / r2, tt = A() + B() / r2;
    return {rr * c * c + tt * s * s, rr * s * s + tt * c * c, (rr - tt) * c * s};
  }
  double radial_displacement(double r, const Material& m) const {
    return (1 + m.nu) / m.E * ((1 - 2 * m.nu) * A() * r + B() / r);
  }
};

// The quarter ring x, y >= 0 as a polygon with nodes on the circles, m elements on the inner arc (element
// size ~ pi/(2m)): symmetry conditions u_y = 0, t_x = 0 on y = 0 and u_x = 0, t_y = 0 on x = 0 (they remove the
// rigid motions), a free outer arc and the pressure t = -p n on the inner polygon's sides.
inline BoundaryProblem quarter_ring(const Lame& lame, int m) {
  BoundaryProblem problem;
  problem.material = kSteel;
  const int radial = std::max(1, static_cast<int>(std::lround(m * (lame.b - lame.a) / (kPi / 2 * lame.a))));
  const int outer = 2 * m;
  std::vector<int> kind;  // 0 bottom, 1 outer, 2 left, 3 inner
  for (int j = 0; j < radial; ++j, kind.push_back(0))
    problem.nodes.emplace_back(lame.a + (lame.b - lame.a) * j / radial, 0.0);
  for (int j = 0; j < outer; ++j, kind.push_back(1))
    problem.nodes.push_back(lame.b * Vector2d(std::cos(kPi / 2 * j / outer), std::sin(kPi / 2 * j / outer)));
  for (int j = 0; j < radial; ++j, kind.push_back(2))
    problem.nodes.emplace_back(0.0, lame.b - (lame.b - lame.a) * j / radial);
  for (int j = 0; j < m; ++j, kind.push_back(3))
    problem.nodes.push_back(lame.a * Vector2d(std::cos(kPi / 2 * (m - j) / m), std::sin(kPi / 2 * (m - j) / m)));
  const std::size_t n = problem.nodes.size();
  for (std::size_t e = 0; e < n; ++e) {
    ElementData data;  // zero values: symmetry displacements and free tractions are 0
    if (kind[e] == 0) data.displacement_prescribed = {false, true};
    if (kind[e] == 2) data.displacement_prescribed = {true, false};
    if (kind[e] == 3) {
      const Vector2d t = (problem.nodes[(e + 1) % n] - problem.nodes[e]).normalized(), normal(t.y(), -t.x());
      data.value.col(0) = data.value.col(1) = -lame.p * normal;
    }
    problem.elements.push_back(data);
  }
  return problem;
}


// The disc of radius 1 as a polygon of n nodes with the quadratic field: displacements on the first quarter of
// the boundary, tractions on the rest (docs/bem.md's timings and bench/bench_hbem).
inline BoundaryProblem disc_problem(int n) {
  const Field field = quadratic_field(kSteel);
  std::vector<Vector2d> corners;
  for (int k = 0; k < n; ++k) corners.emplace_back(std::cos(2 * kPi * k / n), std::sin(2 * kPi * k / n));
  std::vector<SideCondition> sides(static_cast<std::size_t>(n), kTraction);
  for (int k = 0; k < n / 4; ++k) sides[static_cast<std::size_t>(k)] = kDisplacement;
  return polygon_problem(corners, sides, 10.0, field, kSteel);
}

// n points spread over the disc r <= 0.95 (a sunflower pattern: uniform density, no two alike).
inline std::vector<Vector2d> interior_points(int n) {
  std::vector<Vector2d> points;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double r = 0.95 * std::sqrt((k + 0.5) / n);
    points.emplace_back(r * std::cos(golden * k), r * std::sin(golden * k));
  }
  return points;
}

}  // namespace contact::bem::test_problems
