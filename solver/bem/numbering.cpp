// The collocation system's numbering and element coefficients, shared by the dense solve() (collocation.cpp)
// and the hierarchical one (hierarchical_solve.cpp): docs/bem.md, "Discretisation".
#include <cmath>

#include "collocation.hpp"
#include "quadrature.hpp"

namespace contact::bem {

namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

Numbering number_unknowns_and_equations(const BoundaryProblem& problem, const BoundaryGeometry& geometry) {
  const int n = static_cast<int>(problem.nodes.size());
  Numbering num;
  num.displacement.assign(static_cast<std::size_t>(n), {-1, -1});
  num.traction.assign(static_cast<std::size_t>(n), {{{-1, -1}, {-1, -1}}});
  num.known_displacement = Eigen::MatrixX2d::Zero(n, 2);

  // Point 0..n-1 are the nodes; shifted points are added on demand, at most one per (node, side).
  for (int i = 0; i < n; ++i) {
    CollocationPoint p;
    p.position = problem.nodes[static_cast<std::size_t>(i)];
    p.home_node = i;
    p.node = i;
    num.points.push_back(p);
  }
  std::vector<std::array<int, 2>> shifted(static_cast<std::size_t>(n), {-1, -1});  // [node][before/after]
  // (Returns a reference into num.points: use it at once, the next call may reallocate.)
  const auto shifted_point = [&](int node, int side) -> CollocationPoint& {
    int& index = shifted[static_cast<std::size_t>(node)][static_cast<std::size_t>(side)];
    if (index < 0) {
      const int element = side == 0 ? (node + n - 1) % n : node;
      const BoundaryElement& el = geometry.elements[static_cast<std::size_t>(element)];
      CollocationPoint p;
      p.element = element;
      p.s = side == 0 ? (1.0 - kCornerShift) * el.length : kCornerShift * el.length;
      p.position = el.start + p.s * el.tangent;
      p.home_node = node;
      index = static_cast<int>(num.points.size());
      num.points.push_back(p);
    }
    return num.points[static_cast<std::size_t>(index)];
  };

  for (int i = 0; i < n; ++i) {
    const int before = (i + n - 1) % n, after = i;
    const ElementData& data_before = problem.elements[static_cast<std::size_t>(before)];
    const ElementData& data_after = problem.elements[static_cast<std::size_t>(after)];
    const BoundaryElement& el_before = geometry.elements[static_cast<std::size_t>(before)];
    const BoundaryElement& el_after = geometry.elements[static_cast<std::size_t>(after)];
    const bool straight = std::abs(cross(el_before.tangent, el_after.tangent)) < kStraightTolerance &&
                          el_before.tangent.dot(el_after.tangent) > 0.0;
    for (int c = 0; c < 2; ++c) {
      const auto k = static_cast<std::size_t>(c);
      const bool known_before = data_before.displacement_prescribed[k];
      const bool known_after = data_after.displacement_prescribed[k];
      if (!known_before && !known_after) {  // free displacement, known tractions on both sides
        num.displacement[static_cast<std::size_t>(i)][k] = num.unknowns++;
        num.points[static_cast<std::size_t>(i)].equation[k] = num.equations++;  // at the node
        continue;
      }
      num.known_displacement(i, c) = known_after ? data_after.value(c, 0) : data_before.value(c, 1);
      if (known_before && known_after && !straight) {  // corner with two traction unknowns
        num.traction[static_cast<std::size_t>(before)][k][1] = num.unknowns++;
        num.traction[static_cast<std::size_t>(after)][k][0] = num.unknowns++;
        shifted_point(i, 0).equation[k] = num.equations++;
        shifted_point(i, 1).equation[k] = num.equations++;
        continue;
      }
      const int traction = num.unknowns++;  // one traction unknown, shared at a straight node
      if (known_before) num.traction[static_cast<std::size_t>(before)][k][1] = traction;
      if (known_after) num.traction[static_cast<std::size_t>(after)][k][0] = traction;
      num.points[static_cast<std::size_t>(i)].equation[k] = num.equations++;  // at the node
    }
  }
  return num;
}

ElementCoefficients element_coefficients(const KelvinSolution& kelvin, const BoundaryElement& el,
                                         const CollocationPoint& point, int element, int n) {
  ElementCoefficients out;
  // Where does the point lie on this element? On it (s_xi), or off it (-1).
  double s_xi = -1.0;
  bool off_node = false;
  if (point.node >= 0) {
    if (element == point.node) s_xi = 0.0;
    if ((element + 1) % n == point.node) s_xi = el.length;
  } else if (point.element == element) {
    s_xi = point.s;
    off_node = true;
  }
  if (s_xi < 0.0) {  // regular or nearly singular: adaptive Gauss-Legendre
    for (int m = 0; m < 2; ++m) {
      out.h[static_cast<std::size_t>(m)].setZero();
      out.g[static_cast<std::size_t>(m)].setZero();
    }
    integrate_adaptively(el.start, el.tangent, 0.0, el.length, point.position, [&](double s, double w) {
      const Eigen::Vector2d r = el.start + s * el.tangent - point.position;
      const Eigen::Matrix2d u = kelvin.displacement(r), t = kelvin.traction(r, el.normal);
      const double n1 = s / el.length, n0 = 1.0 - n1;
      out.h[0] += (w * n0) * t;
      out.h[1] += (w * n1) * t;
      out.g[0] += (w * n0) * u;
      out.g[1] += (w * n1) * u;
    });
    return out;
  }
  // The point lies on this straight element: closed forms (quadrature.hpp, kelvin.hpp).
  // U = k [ (3 - 4 nu) ln(R / r) I + t t^T ]; T = k_odd / (s - s_xi) [[0, -1], [1, 0]] (a principal value).
  const double nu = kelvin.constants().poisson_ratio;
  const Eigen::Vector2d logs = log_moments(el.length, s_xi);
  const Eigen::Vector2d principal = cauchy_moments(el.length, s_xi);
  Eigen::Matrix2d odd;
  odd << 0.0, -1.0, 1.0, 0.0;
  const Eigen::Matrix2d tt = el.tangent * el.tangent.transpose();
  for (int m = 0; m < 2; ++m) {
    const auto k = static_cast<std::size_t>(m);
    const double half_length = 0.5 * el.length;  // int N_m ds
    out.g[k] =
        kelvin.displacement_factor() *
        ((3.0 - 4.0 * nu) * (std::log(kelvin.log_scale()) * half_length + logs(m)) * Eigen::Matrix2d::Identity() +
         half_length * tt);
    out.h[k] = kelvin.odd_traction_factor() * principal(m) * odd;
    if (off_node) {
      // Free term c = I/2 at a point inside a straight element, shared by the shape functions.
      const double shape = m == 0 ? 1.0 - s_xi / el.length : s_xi / el.length;
      out.h[k] += 0.5 * shape * Eigen::Matrix2d::Identity();
    }
  }
  if (!off_node) out.skip[s_xi == 0.0 ? 0 : 1] = true;
  return out;
}

BoundarySolution collect_solution(const BoundaryProblem& problem, const Numbering& num, const Eigen::VectorXd& x,
                                  double traction_scale) {
  const int n = static_cast<int>(problem.nodes.size());
  BoundarySolution solution;
  solution.displacement = num.known_displacement;
  solution.traction.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 2; ++c) {
      const int index = num.displacement[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)];
      if (index >= 0) solution.displacement(i, c) = x(index);
    }
  for (int e = 0; e < n; ++e) {
    Eigen::Matrix2d& t = solution.traction[static_cast<std::size_t>(e)];
    t = problem.elements[static_cast<std::size_t>(e)].value;
    for (int c = 0; c < 2; ++c)
      for (int end = 0; end < 2; ++end) {
        const int index =
            num.traction[static_cast<std::size_t>(e)][static_cast<std::size_t>(c)][static_cast<std::size_t>(end)];
        if (index >= 0) t(c, end) = traction_scale * x(index);
      }
  }
  return solution;
}

}  // namespace contact::bem
