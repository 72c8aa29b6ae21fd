#include "kelvin.hpp"

#include <cmath>

namespace contact::bem {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

ElasticConstants effective_constants(const Material& material) {
  const double mu = material.E / (2.0 * (1.0 + material.nu));  // the same in plane strain and plane stress
  const double nu = material.plane_strain ? material.nu : material.nu / (1.0 + material.nu);
  return {mu, nu};
}

Eigen::Vector3d hooke_stress(const ElasticConstants& c, const Eigen::Matrix2d& g) {
  const double lambda = c.lame_lambda(), mu = c.shear_modulus;
  const double trace = g(0, 0) + g(1, 1);
  return {lambda * trace + 2.0 * mu * g(0, 0), lambda * trace + 2.0 * mu * g(1, 1), mu * (g(0, 1) + g(1, 0))};
}

KelvinSolution::KelvinSolution(const ElasticConstants& constants, double log_scale)
    : constants_(constants),
      log_scale_(log_scale),
      nu_(constants.poisson_ratio),
      u_factor_(1.0 / (8.0 * kPi * constants.shear_modulus * (1.0 - constants.poisson_ratio))),
      t_factor_(1.0 / (4.0 * kPi * (1.0 - constants.poisson_ratio))),
      s_factor_(constants.shear_modulus / (2.0 * kPi * (1.0 - constants.poisson_ratio))) {}

Eigen::Matrix2d KelvinSolution::displacement(const Eigen::Vector2d& r) const {
  const double length = r.norm();
  const Eigen::Vector2d d = r / length;
  Eigen::Matrix2d u = d * d.transpose();
  u.diagonal().array() += (3.0 - 4.0 * nu_) * std::log(log_scale_ / length);
  return u_factor_ * u;
}

Eigen::Matrix2d KelvinSolution::traction(const Eigen::Vector2d& r, const Eigen::Vector2d& n) const {
  const double length = r.norm();
  const Eigen::Vector2d d = r / length;
  const double drdn = d.dot(n);
  const double a = 1.0 - 2.0 * nu_;
  Eigen::Matrix2d t = drdn * (2.0 * d * d.transpose());
  t.diagonal().array() += drdn * a;
  t -= a * (d * n.transpose() - n * d.transpose());
  return (-t_factor_ / length) * t;
}

Eigen::Matrix<double, 3, 2> KelvinSolution::stress_by_traction(const Eigen::Vector2d& r) const {
  const double length = r.norm();
  const Eigen::Vector2d d = r / length;
  const double a = 1.0 - 2.0 * nu_;
  constexpr int kI[3] = {0, 1, 0}, kJ[3] = {0, 1, 1};
  Eigen::Matrix<double, 3, 2> D;
  for (int row = 0; row < 3; ++row) {
    const int i = kI[row], j = kJ[row];
    for (int k = 0; k < 2; ++k) {
      const double dki = k == i, dkj = k == j, dij = i == j;
      D(row, k) = a * (dki * d(j) + dkj * d(i) - dij * d(k)) + 2.0 * d(i) * d(j) * d(k);
    }
  }
  return (t_factor_ / length) * D;
}

Eigen::Matrix<double, 3, 2> KelvinSolution::stress_by_displacement(const Eigen::Vector2d& r,
                                                                   const Eigen::Vector2d& n) const {
  const double length = r.norm();
  const Eigen::Vector2d d = r / length;
  const double drdn = d.dot(n);
  const double a = 1.0 - 2.0 * nu_;
  constexpr int kI[3] = {0, 1, 0}, kJ[3] = {0, 1, 1};
  Eigen::Matrix<double, 3, 2> S;
  for (int row = 0; row < 3; ++row) {
    const int i = kI[row], j = kJ[row];
    for (int k = 0; k < 2; ++k) {
      const double dik = i == k, djk = j == k, dij = i == j;
      S(row, k) = 2.0 * drdn * (a * dij * d(k) + nu_ * (dik * d(j) + djk * d(i)) - 4.0 * d(i) * d(j) * d(k)) +
                  2.0 * nu_ * (n(i) * d(j) * d(k) + n(j) * d(i) * d(k)) +
                  a * (2.0 * n(k) * d(i) * d(j) + n(j) * dik + n(i) * djk) - (1.0 - 4.0 * nu_) * n(k) * dij;
    }
  }
  return (s_factor_ / (length * length)) * S;
}

}  // namespace contact::bem
