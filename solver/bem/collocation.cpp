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
#include "collocation.hpp"
#include "kelvin.hpp"
#include "quadrature.hpp"

namespace contact::bem {

namespace {

constexpr double kSingularTolerance = 1e-14;  // reciprocal condition number below this: singular system

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

  return collect_solution(problem, num, x, traction_scale);
}

}  // namespace contact::bem
