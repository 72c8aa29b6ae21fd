#include "elasticity.hpp"

#include <Eigen/LU>

#include <cmath>

namespace contact::fem {

namespace {
const double g = 1.0 / std::sqrt(3.0);
}

const std::array<Eigen::Vector2d, 4> kGaussPoints = {Eigen::Vector2d(-g, -g), Eigen::Vector2d(g, -g),
                                                     Eigen::Vector2d(g, g), Eigen::Vector2d(-g, g)};

Elasticity make_elasticity(const Material& m, const Model& model) {
  Elasticity el;
  const double E = m.E, nu = m.nu;
  if (model.plane == Plane::strain) {
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    el.D << lambda + 2 * mu, lambda, 0, lambda, lambda + 2 * mu, 0, 0, 0, mu;
    el.nu_zz = nu;
    el.thickness = 1.0;
  } else {
    const double f = E / (1 - nu * nu);
    el.D << f, f * nu, 0, f * nu, f, 0, 0, 0, f * (1 - nu) / 2;
    el.nu_zz = 0.0;
    el.thickness = model.thickness;
  }
  return el;
}

Eigen::Matrix<double, 4, 2> cell_coordinates(const mesh::Mesh& m, int cell) {
  Eigen::Matrix<double, 4, 2> x;
  const auto& c = m.cells[static_cast<size_t>(cell)];
  for (int k = 0; k < 4; ++k) x.row(k) = m.nodes[static_cast<size_t>(c[static_cast<size_t>(k)])].transpose();
  return x;
}

Matrix38d strain_matrix(const Eigen::Matrix<double, 4, 2>& x, double xi, double eta, double& det_j) {
  // Reference derivatives of the bilinear shape functions N_k = (1 + xi_k xi)(1 + eta_k eta) / 4.
  static const double xs[4] = {-1, 1, 1, -1}, es[4] = {-1, -1, 1, 1};
  Eigen::Matrix<double, 2, 4> dref;
  for (int k = 0; k < 4; ++k) {
    dref(0, k) = 0.25 * xs[k] * (1 + es[k] * eta);
    dref(1, k) = 0.25 * es[k] * (1 + xs[k] * xi);
  }
  const Eigen::Matrix2d J = dref * x;  // J(i, j) = d x_j / d ref_i
  det_j = J.determinant();
  const Eigen::Matrix<double, 2, 4> dN = J.inverse() * dref;  // physical derivatives
  Matrix38d B = Matrix38d::Zero();
  for (int k = 0; k < 4; ++k) {
    B(0, 2 * k) = dN(0, k);
    B(1, 2 * k + 1) = dN(1, k);
    B(2, 2 * k) = dN(1, k);
    B(2, 2 * k + 1) = dN(0, k);
  }
  return B;
}

Matrix8d element_stiffness(const Eigen::Matrix<double, 4, 2>& x, const Elasticity& el) {
  Matrix8d K = Matrix8d::Zero();
  for (const auto& gp : kGaussPoints) {
    double det_j = 0;
    const Matrix38d B = strain_matrix(x, gp.x(), gp.y(), det_j);
    K.noalias() += B.transpose() * el.D * B * (det_j * el.thickness);
  }
  return 0.5 * (K + K.transpose());  // exactly symmetric
}

Vector8d element_body_force(const Eigen::Matrix<double, 4, 2>& x, const Eigen::Vector2d& force, const Elasticity& el) {
  static const double xs[4] = {-1, 1, 1, -1}, es[4] = {-1, -1, 1, 1};
  Vector8d f = Vector8d::Zero();
  for (const auto& gp : kGaussPoints) {
    double det_j = 0;
    strain_matrix(x, gp.x(), gp.y(), det_j);
    for (int k = 0; k < 4; ++k) {
      const double N = 0.25 * (1 + xs[k] * gp.x()) * (1 + es[k] * gp.y());
      f.segment<2>(2 * k) += N * force * det_j * el.thickness;
    }
  }
  return f;
}

Eigen::Matrix<double, 3, 4> gauss_stresses(const Eigen::Matrix<double, 4, 2>& x, const Vector8d& u,
                                           const Elasticity& el) {
  Eigen::Matrix<double, 3, 4> s;
  for (int q = 0; q < 4; ++q) {
    double det_j = 0;
    const Matrix38d B =
        strain_matrix(x, kGaussPoints[static_cast<size_t>(q)].x(), kGaussPoints[static_cast<size_t>(q)].y(), det_j);
    s.col(q) = el.D * (B * u);
  }
  return s;
}

Eigen::Matrix<double, 4, 3> extrapolate_to_corners(const Eigen::Matrix<double, 3, 4>& gauss_values) {
  // In the coordinates r = sqrt(3) xi the Gauss points sit at the corners (+-1, +-1) and the element's corners
  // at (+-sqrt 3, +-sqrt 3): evaluate the bilinear interpolant of the Gauss values there.
  static const double xs[4] = {-1, 1, 1, -1}, es[4] = {-1, -1, 1, 1};
  const double r = std::sqrt(3.0);
  Eigen::Matrix<double, 4, 3> out;
  for (int corner = 0; corner < 4; ++corner) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (int q = 0; q < 4; ++q) {
      const double L = 0.25 * (1 + xs[q] * xs[corner] * r) * (1 + es[q] * es[corner] * r);
      v += L * gauss_values.col(q);
    }
    out.row(corner) = v.transpose();
  }
  return out;
}

double von_mises(double sxx, double syy, double sxy, double szz) {
  return std::sqrt(0.5 * ((sxx - syy) * (sxx - syy) + (syy - szz) * (syy - szz) + (szz - sxx) * (szz - sxx)) +
                   3.0 * sxy * sxy);
}

}  // namespace contact::fem
