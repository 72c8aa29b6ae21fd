// solve(): the collocation system of the boundary integral equation (docs/bem.md, "Discretisation").
//
//   c_lj(xi) u_j(xi) + int T_lj(xi, x) u_j(x) dGamma = int U_lj(xi, x) t_j(x) dGamma
//
// Unknowns, per node and component c: the displacement if neither adjacent element prescribes it, else the
// traction at that node of each adjacent element that prescribes the displacement. Equations, likewise per node
// and component: the collocation equation at the node; but where both adjacent elements prescribe the
// displacement component at a true corner (two traction unknowns), two collocation equations at points shifted
// into the two elements, a quarter of an element from the corner. At a straight node (hanging nodes) the two
// tractions are one unknown (traction continuity) and the nodal equation suffices.
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bem.hpp"
#include "boundary.hpp"
#include "kelvin.hpp"
#include "quadrature.hpp"

namespace contact::bem {

namespace {

constexpr double kCornerShift = 0.25;         // shifted collocation points: this fraction of the element in
constexpr double kStraightTolerance = 1e-8;   // |sin(turning angle)| below this: a straight node
constexpr double kSingularTolerance = 1e-14;  // reciprocal condition number below this: singular system

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// A collocation point: a node, or a point inside an element at arc length s. equation[l] is the row of the
// collocation equation in direction l, or -1 where this point does not supply that equation.
struct CollocationPoint {
  Eigen::Vector2d position;
  int node = -1;
  int element = -1;
  double s = 0.0;
  std::array<int, 2> equation{-1, -1};
};

// Unknown numbering: displacement[i][c] and traction[e][c][end] hold an unknown's index or -1 where the value is
// prescribed (known_displacement / problem values then hold it).
struct Numbering {
  std::vector<std::array<int, 2>> displacement;
  std::vector<std::array<std::array<int, 2>, 2>> traction;
  Eigen::MatrixX2d known_displacement;
  int unknowns = 0;
  std::vector<CollocationPoint> points;
  int equations = 0;
};

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

// The coefficients of one element in one collocation point's equations: h[m](l, j) multiplies u_j at the
// element's node m, g[m](l, j) the traction t_j at its end m. skip[m]: the coefficient is singular and left to
// the rigid-body identity (the collocation node's own shape function on its two elements).
struct ElementCoefficients {
  std::array<Eigen::Matrix2d, 2> h, g;
  std::array<bool, 2> skip{false, false};
};

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

}  // namespace

BoundarySolution solve(const BoundaryProblem& problem) {
  const BoundaryGeometry geometry = check_problem(problem);
  check_rigid_motions(problem, geometry);
  const int n = static_cast<int>(problem.nodes.size());
  const ElasticConstants constants = effective_constants(problem.material);
  const KelvinSolution kelvin(constants, log_scale(geometry));
  const Numbering num = number_unknowns_and_equations(problem, geometry);
  if (num.unknowns != num.equations)
    throw std::logic_error("bem: " + std::to_string(num.unknowns) + " unknowns but " + std::to_string(num.equations) +
                           " equations");

  // Traction unknowns are scaled to displacement units, tau = t diameter / mu, so that all columns are O(1).
  const double traction_scale = constants.shear_modulus / geometry.diameter;  // t = traction_scale * tau
  // Row-major while assembling: each collocation point fills its own rows, so the writes stay contiguous.
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  RowMajorMatrix matrix = RowMajorMatrix::Zero(num.unknowns, num.unknowns);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(num.unknowns);

  for (const CollocationPoint& point : num.points) {
    if (point.equation[0] < 0 && point.equation[1] < 0) continue;  // a corner node with shifted equations only
    // Scatter h (multiplying the displacement of `node`) and g (the traction of `element` at `end`) into this
    // point's equations: unknowns to the matrix, prescribed values to the right-hand side.
    const auto add_displacement = [&](int node, const Eigen::Matrix2d& h) {
      for (int l = 0; l < 2; ++l) {
        const int row = point.equation[static_cast<std::size_t>(l)];
        if (row < 0) continue;
        for (int j = 0; j < 2; ++j) {
          const int column = num.displacement[static_cast<std::size_t>(node)][static_cast<std::size_t>(j)];
          if (column >= 0)
            matrix(row, column) += h(l, j);
          else
            rhs(row) -= h(l, j) * num.known_displacement(node, j);
        }
      }
    };
    const auto add_traction = [&](int element, int end, const Eigen::Matrix2d& g) {
      const ElementData& data = problem.elements[static_cast<std::size_t>(element)];
      for (int l = 0; l < 2; ++l) {
        const int row = point.equation[static_cast<std::size_t>(l)];
        if (row < 0) continue;
        for (int j = 0; j < 2; ++j) {
          const int column = num.traction[static_cast<std::size_t>(element)][static_cast<std::size_t>(j)]
                                         [static_cast<std::size_t>(end)];
          if (column >= 0)
            matrix(row, column) -= g(l, j) * traction_scale;
          else
            rhs(row) += g(l, j) * data.value(j, end);
        }
      }
    };

    // Rigid-body identity at a node: c + PV int T over the whole boundary = 0 (a rigid translation gives no
    // traction), so the node's own coefficient, free term included, is minus the sum of all the others. This
    // gives the correct free term at corners and makes the strongly singular integrals unnecessary.
    Eigen::Matrix2d others = Eigen::Matrix2d::Zero();
    for (int e = 0; e < n; ++e) {
      const BoundaryElement& el = geometry.elements[static_cast<std::size_t>(e)];
      const ElementCoefficients coefficients = element_coefficients(kelvin, el, point, e, n);
      const std::array<int, 2> nodes{e, (e + 1) % n};
      for (std::size_t m = 0; m < 2; ++m) {
        add_traction(e, static_cast<int>(m), coefficients.g[m]);
        if (coefficients.skip[m]) continue;
        add_displacement(nodes[m], coefficients.h[m]);
        others += coefficients.h[m];
      }
    }
    if (point.node >= 0) add_displacement(point.node, -others);
  }

  // In place: the factors overwrite the matrix, so the dense storage is needed once (8 unknowns^2 bytes).
  const Eigen::PartialPivLU<Eigen::Ref<RowMajorMatrix>> lu(matrix);
  const double rcond = lu.rcond();
  if (!(rcond > kSingularTolerance))
    throw std::runtime_error("bem: the collocation matrix is singular (reciprocal condition number " +
                             std::to_string(rcond) + ")");
  const Eigen::VectorXd x = lu.solve(rhs);

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
