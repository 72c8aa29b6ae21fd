// P1 plane elasticity on one linear triangle (the constant-strain triangle): strain matrix, stiffness, loads.
//
// Same conventions as the Q1 element (elasticity.hpp): dof = 2 * local node + component, stresses (sxx, syy, sxy),
// every quantity includes the thickness. The strain is constant over the triangle, so the stiffness
// B^T D B |T| t is exact with one point, and so is the consistent load of a constant body force (|T| t f / 3 at
// each node).
#pragma once

#include "elasticity.hpp"

#include <Eigen/Core>

namespace contact::fem {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;

// The constant strain-displacement matrix of the triangle with corners x (rows = local nodes, counter-clockwise);
// area receives its signed area.
Matrix36d triangle_strain_matrix(const Eigen::Matrix<double, 3, 2>& x, double& area);

Matrix6d triangle_stiffness(const Eigen::Matrix<double, 3, 2>& x, const Elasticity& el);
Vector6d triangle_body_force(const Eigen::Matrix<double, 3, 2>& x, const Eigen::Vector2d& force, const Elasticity& el);

// The in-plane stress (sxx, syy, sxy), constant over the triangle, for element displacements u.
Eigen::Vector3d triangle_stress(const Eigen::Matrix<double, 3, 2>& x, const Vector6d& u, const Elasticity& el);

}  // namespace contact::fem
