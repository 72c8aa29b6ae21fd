// Q1 plane elasticity on one quadrilateral: material matrix, stiffness, loads, stresses.
//
// DOF numbering everywhere in the solver: dof = 2 * node + component (0 = x, 1 = y). Stress vectors are
// (sxx, syy, sxy) in the plane and szz separately (plane strain: szz = nu (sxx + syy); plane stress: 0).
// All element quantities include the out-of-plane thickness (1 in plane strain), so forces are totals.
#pragma once

#include "contact/mesh.hpp"
#include "contact/problem.hpp"

#include <Eigen/Core>

#include <array>

namespace contact::fem {

using Matrix8d = Eigen::Matrix<double, 8, 8>;
using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix38d = Eigen::Matrix<double, 3, 8>;

struct Elasticity {
  Eigen::Matrix3d D;   // stress = D * (exx, eyy, gxy)
  double nu_zz = 0.0;  // szz = nu_zz * (sxx + syy)
  double thickness = 1.0;
};

Elasticity make_elasticity(const Material& m, const Model& model);

// 2x2 Gauss points on the reference square [-1, 1]^2, in the order of the element's nodes.
extern const std::array<Eigen::Vector2d, 4> kGaussPoints;

// Corner coordinates of a cell as a 4x2 matrix (rows = local nodes).
Eigen::Matrix<double, 4, 2> cell_coordinates(const mesh::Mesh& m, int cell);

// Strain-displacement matrix at reference point (xi, eta); det_j receives the Jacobian determinant.
Matrix38d strain_matrix(const Eigen::Matrix<double, 4, 2>& x, double xi, double eta, double& det_j);

// Element stiffness (2x2 Gauss) and the consistent load of a constant body force per volume.
Matrix8d element_stiffness(const Eigen::Matrix<double, 4, 2>& x, const Elasticity& el);
Vector8d element_body_force(const Eigen::Matrix<double, 4, 2>& x, const Eigen::Vector2d& force, const Elasticity& el);

// In-plane stresses (sxx, syy, sxy) at the four Gauss points (columns) for element displacements u.
Eigen::Matrix<double, 3, 4> gauss_stresses(const Eigen::Matrix<double, 4, 2>& x, const Vector8d& u,
                                           const Elasticity& el);

// Values at the four Gauss points extrapolated (bilinearly) to the four corners: row k = corner k.
Eigen::Matrix<double, 4, 3> extrapolate_to_corners(const Eigen::Matrix<double, 3, 4>& gauss_values);

double von_mises(double sxx, double syy, double sxy, double szz);

}  // namespace contact::fem
