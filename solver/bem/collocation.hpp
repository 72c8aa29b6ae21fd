// Internal to solver/bem: the collocation system's numbering of unknowns and equations and the coefficients of
// one element at one collocation point (docs/bem.md, "Discretisation"). The dense solve() (collocation.cpp)
// assembles them into one matrix; the hierarchical solve (hierarchical_solve.cpp) evaluates them block by block.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "bem.hpp"
#include "boundary.hpp"
#include "kelvin.hpp"

namespace contact::bem {

constexpr double kCornerShift = 0.25;        // shifted collocation points: this fraction of the element in
constexpr double kStraightTolerance = 1e-8;  // |sin(turning angle)| below this: a straight node

// A collocation point: a node, or a point inside an element at arc length s. equation[l] is the row of the
// collocation equation in direction l, or -1 where this point does not supply that equation. home_node: the node
// whose equations the point carries (itself, or the corner a shifted point belongs to).
struct CollocationPoint {
  Eigen::Vector2d position;
  int node = -1;
  int element = -1;
  double s = 0.0;
  int home_node = -1;
  std::array<int, 2> equation{-1, -1};
};

// Unknown numbering: displacement[i][c] and traction[e][c][end] hold an unknown's index or -1 where the value is
// prescribed (known_displacement / problem values then hold it). Every node carries as many equations as
// unknowns, component by component (docs/bem.md, the table of unknowns), which the hierarchical solve uses to
// group both by node.
struct Numbering {
  std::vector<std::array<int, 2>> displacement;
  std::vector<std::array<std::array<int, 2>, 2>> traction;
  Eigen::MatrixX2d known_displacement;
  int unknowns = 0;
  std::vector<CollocationPoint> points;
  int equations = 0;
};

Numbering number_unknowns_and_equations(const BoundaryProblem& problem, const BoundaryGeometry& geometry);

// The coefficients of one element in one collocation point's equations: h[m](l, j) multiplies u_j at the
// element's node m, g[m](l, j) the traction t_j at its end m. skip[m]: the coefficient is singular and left to
// the rigid-body identity (the collocation node's own shape function on its two elements).
struct ElementCoefficients {
  std::array<Eigen::Matrix2d, 2> h, g;
  std::array<bool, 2> skip{false, false};
};

ElementCoefficients element_coefficients(const KelvinSolution& kelvin, const BoundaryElement& el,
                                         const CollocationPoint& point, int element, int n);

// The complete boundary state from the solved unknowns x (traction unknowns in the scaled units
// tau = t / traction_scale) and the prescribed values.
BoundarySolution collect_solution(const BoundaryProblem& problem, const Numbering& num, const Eigen::VectorXd& x,
                                  double traction_scale);

}  // namespace contact::bem
