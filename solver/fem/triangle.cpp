#include "triangle.hpp"

namespace contact::fem {

Matrix36d triangle_strain_matrix(const Eigen::Matrix<double, 3, 2>& x, double& area) {
  // N_k = (a_k + b_k x + c_k y) / (2 A) with b_k = y_{k+1} - y_{k+2}, c_k = x_{k+2} - x_{k+1} (indices mod 3).
  area = 0.5 * ((x(1, 0) - x(0, 0)) * (x(2, 1) - x(0, 1)) - (x(2, 0) - x(0, 0)) * (x(1, 1) - x(0, 1)));
  Matrix36d B = Matrix36d::Zero();
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double dx = (x(i, 1) - x(j, 1)) / (2 * area);  // dN_k / dx
    const double dy = (x(j, 0) - x(i, 0)) / (2 * area);  // dN_k / dy
    B(0, 2 * k) = dx;
    B(1, 2 * k + 1) = dy;
    B(2, 2 * k) = dy;
    B(2, 2 * k + 1) = dx;
  }
  return B;
}

Matrix6d triangle_stiffness(const Eigen::Matrix<double, 3, 2>& x, const Elasticity& el) {
  double area = 0;
  const Matrix36d B = triangle_strain_matrix(x, area);
  const Matrix6d K = B.transpose() * el.D * B * (area * el.thickness);
  return 0.5 * (K + K.transpose());  // exactly symmetric
}

Vector6d triangle_body_force(const Eigen::Matrix<double, 3, 2>& x, const Eigen::Vector2d& force, const Elasticity& el) {
  const double area = 0.5 * ((x(1, 0) - x(0, 0)) * (x(2, 1) - x(0, 1)) - (x(2, 0) - x(0, 0)) * (x(1, 1) - x(0, 1)));
  Vector6d f;
  for (int k = 0; k < 3; ++k) f.segment<2>(2 * k) = force * (area * el.thickness / 3.0);
  return f;
}

Eigen::Vector3d triangle_stress(const Eigen::Matrix<double, 3, 2>& x, const Vector6d& u, const Elasticity& el) {
  double area = 0;
  return el.D * (triangle_strain_matrix(x, area) * u);
}

}  // namespace contact::fem
