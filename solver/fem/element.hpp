// The finite element of one mesh cell, whatever its kind: the bilinear quadrilateral (Q1, elasticity.hpp) or the
// linear triangle (P1, triangle.hpp). The solver's element loops, the stresses and the error indicators go through
// these functions, so that they work on quadrilateral, triangle and mixed meshes alike.
//
// The matrices have a fixed maximum size (8 dofs, 4 nodes or points) and a run-time size, so nothing is allocated
// per cell.
#pragma once

#include "elasticity.hpp"

#include <Eigen/Core>

#include <array>

namespace contact::fem {

using CellMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 8, 8>;  // 2n x 2n
using CellVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 8, 1>;               // 2n
using CellDofs = Eigen::Matrix<int, Eigen::Dynamic, 1, 0, 8, 1>;                    // 2n
using PointStresses = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 4>;            // (sxx, syy, sxy) x points
using NodeStresses = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, 4, 3>;             // nodes x (sxx, syy, sxy)

// The cell's dofs, 2 per node in the cell's node order (dof = 2 node + component).
CellDofs cell_dofs(const mesh::Cell& cell);

// The points at which a cell's stresses are evaluated and its error norms integrated: the 2x2 Gauss points of a
// quadrilateral; for a triangle the three-point rule at (1/6, 1/6), (2/3, 1/6), (1/6, 2/3) (degree 2: exact for
// the products of linear functions that the indicators integrate).
struct CellQuadrature {
  int size = 0;
  std::array<Eigen::Vector2d, 4> point;                                  // physical coordinates
  std::array<double, 4> weight{};                                        // |J| w: they sum to the cell's area
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4> shape;  // (point, node): the shape functions
};
CellQuadrature cell_quadrature(const mesh::Mesh& m, int cell);

// Element stiffness and the consistent load of a constant body force per volume (thickness included).
CellMatrix cell_stiffness(const mesh::Mesh& m, int cell, const Elasticity& el);
CellVector cell_body_force(const mesh::Mesh& m, int cell, const Eigen::Vector2d& force, const Elasticity& el);

// The cell's entries of a vector of all dofs.
CellVector cell_values(const mesh::Mesh& m, int cell, const Eigen::VectorXd& u);

// In-plane stresses at the cell's quadrature points, for its element displacements ue.
PointStresses cell_point_stresses(const mesh::Mesh& m, int cell, const CellVector& ue, const Elasticity& el);

// The point stresses carried to the cell's nodes: extrapolated bilinearly on a quadrilateral (extrapolate_to_corners),
// the constant on a triangle.
NodeStresses cell_node_stresses(const mesh::Cell& cell, const PointStresses& point_stresses);

}  // namespace contact::fem
