#include "element.hpp"

#include "triangle.hpp"

namespace contact::fem {

namespace {

Eigen::Matrix<double, 3, 2> triangle_coordinates(const mesh::Mesh& m, int cell) {
  Eigen::Matrix<double, 3, 2> x;
  const auto& c = m.cells[static_cast<size_t>(cell)];
  for (int k = 0; k < 3; ++k) x.row(k) = m.nodes[static_cast<size_t>(c[static_cast<size_t>(k)])].transpose();
  return x;
}

// The triangle rule's points in area coordinates (L1, L2, L3 = weights of nodes 0, 1, 2).
const double kTrianglePoints[3][3] = {
    {2.0 / 3, 1.0 / 6, 1.0 / 6}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, {1.0 / 6, 1.0 / 6, 2.0 / 3}};

}  // namespace

CellDofs cell_dofs(const mesh::Cell& cell) {
  CellDofs dofs(2 * cell.size());
  for (int k = 0; k < cell.size(); ++k) {
    dofs[2 * k] = 2 * cell[static_cast<size_t>(k)];
    dofs[2 * k + 1] = 2 * cell[static_cast<size_t>(k)] + 1;
  }
  return dofs;
}

CellQuadrature cell_quadrature(const mesh::Mesh& m, int cell) {
  CellQuadrature q;
  if (m.cells[static_cast<size_t>(cell)].is_triangle()) {
    const auto x = triangle_coordinates(m, cell);
    const double area = m.cell_area(cell);
    q.size = 3;
    q.shape.resize(3, 3);
    for (int p = 0; p < 3; ++p) {
      q.point[static_cast<size_t>(p)] = Eigen::Vector2d::Zero();
      for (int k = 0; k < 3; ++k) {
        q.shape(p, k) = kTrianglePoints[p][k];
        q.point[static_cast<size_t>(p)] += kTrianglePoints[p][k] * x.row(k).transpose();
      }
      q.weight[static_cast<size_t>(p)] = area / 3.0;
    }
    return q;
  }
  static const double xs[4] = {-1, 1, 1, -1}, es[4] = {-1, -1, 1, 1};
  const auto x = cell_coordinates(m, cell);
  q.size = 4;
  q.shape.resize(4, 4);
  for (int p = 0; p < 4; ++p) {
    const auto& gp = kGaussPoints[static_cast<size_t>(p)];
    double det_j = 0;
    strain_matrix(x, gp.x(), gp.y(), det_j);
    q.weight[static_cast<size_t>(p)] = det_j;  // the 2x2 Gauss weights are 1
    q.point[static_cast<size_t>(p)] = Eigen::Vector2d::Zero();
    for (int k = 0; k < 4; ++k) {
      q.shape(p, k) = 0.25 * (1 + xs[k] * gp.x()) * (1 + es[k] * gp.y());
      q.point[static_cast<size_t>(p)] += q.shape(p, k) * x.row(k).transpose();
    }
  }
  return q;
}

CellMatrix cell_stiffness(const mesh::Mesh& m, int cell, const Elasticity& el) {
  if (m.cells[static_cast<size_t>(cell)].is_triangle()) return triangle_stiffness(triangle_coordinates(m, cell), el);
  return element_stiffness(cell_coordinates(m, cell), el);
}

CellVector cell_body_force(const mesh::Mesh& m, int cell, const Eigen::Vector2d& force, const Elasticity& el) {
  if (m.cells[static_cast<size_t>(cell)].is_triangle())
    return triangle_body_force(triangle_coordinates(m, cell), force, el);
  return element_body_force(cell_coordinates(m, cell), force, el);
}

CellVector cell_values(const mesh::Mesh& m, int cell, const Eigen::VectorXd& u) {
  const CellDofs dofs = cell_dofs(m.cells[static_cast<size_t>(cell)]);
  CellVector ue(dofs.size());
  for (Eigen::Index i = 0; i < dofs.size(); ++i) ue[i] = u[dofs[i]];
  return ue;
}

PointStresses cell_point_stresses(const mesh::Mesh& m, int cell, const CellVector& ue, const Elasticity& el) {
  if (m.cells[static_cast<size_t>(cell)].is_triangle()) {
    const Eigen::Vector3d s = triangle_stress(triangle_coordinates(m, cell), ue, el);
    return s.replicate(1, 3);
  }
  return gauss_stresses(cell_coordinates(m, cell), ue, el);
}

NodeStresses cell_node_stresses(const mesh::Cell& cell, const PointStresses& point_stresses) {
  if (cell.is_triangle()) return point_stresses.rowwise().mean().transpose().replicate(3, 1);
  return extrapolate_to_corners(point_stresses);
}

}  // namespace contact::fem
