// Kelvin's fundamental solution of plane-strain elastostatics and the kernels of Somigliana's identities.
//
// Notation (Brebbia & Dominguez, "Boundary Elements: An Introductory Course", ch. 5; the same in Becker,
// "The Boundary Element Method in Engineering"): a unit point force in direction l at the source point xi;
// x is the field point on the boundary; r = x - xi, r = |r|, r_i = r_i / r (the r,i of the books),
// n = outward normal at x, dr/dn = r . n. For plane stress pass the effective constants (bem.hpp, Material).
//   U_lj = 1 / (8 pi mu (1 - nu)) [ (3 - 4 nu) ln(R / r) delta_lj + r_l r_j ]
//   T_lj = -1 / (4 pi (1 - nu) r) [ dr/dn ((1 - 2 nu) delta_lj + 2 r_l r_j) - (1 - 2 nu)(r_l n_j - r_j n_l) ]
//   D_kij = 1 / (4 pi (1 - nu) r) [ (1 - 2 nu)(delta_ki r_j + delta_kj r_i - delta_ij r_k) + 2 r_i r_j r_k ]
//   S_kij = mu / (2 pi (1 - nu) r^2) [ 2 dr/dn ((1 - 2 nu) delta_ij r_k + nu (delta_ik r_j + delta_jk r_i)
//            - 4 r_i r_j r_k) + 2 nu (n_i r_j r_k + n_j r_i r_k) + (1 - 2 nu)(2 n_k r_i r_j + n_j delta_ik
//            + n_i delta_jk) - (1 - 4 nu) n_k delta_ij ]
// U_lj(xi, x) is the displacement in direction j at x; T_lj the traction on a surface of normal n at x.
// Somigliana: u_l(xi) = int U_lj t_j - int T_lj u_j and sigma_ij(xi) = int D_kij t_k - int S_kij u_k.
// The length R (the "log scale") only adds (3 - 4 nu) ln(R) / (8 pi mu (1 - nu)) times the net force int t dGamma,
// which vanishes for any equilibrium state; solve() takes R = 4 x the boundary's diameter, which keeps the
// first-kind (single-layer) part of the equations away from its degenerate scales whatever the user's units.
#pragma once

#include <Eigen/Core>

#include "bem.hpp"

namespace contact::bem {

// The plane-strain constants that represent `material` (plane stress: the effective ones of bem.hpp).
struct ElasticConstants {
  double shear_modulus;
  double poisson_ratio;
  double lame_lambda() const { return 2.0 * shear_modulus * poisson_ratio / (1.0 - 2.0 * poisson_ratio); }
};
ElasticConstants effective_constants(const Material& material);

// Hooke's law with the effective constants: (sxx, syy, sxy) from the displacement gradient grad(i, j) = du_i/dx_j.
Eigen::Vector3d hooke_stress(const ElasticConstants& c, const Eigen::Matrix2d& displacement_gradient);

class KelvinSolution {
 public:
  KelvinSolution(const ElasticConstants& constants, double log_scale);

  // U(l, j) and T(l, j) for r = x - xi (non-zero) and the outward normal n at x.
  Eigen::Matrix2d displacement(const Eigen::Vector2d& r) const;
  Eigen::Matrix2d traction(const Eigen::Vector2d& r, const Eigen::Vector2d& n) const;
  // D and S as 3x2 matrices: column k holds (D_kxx, D_kyy, D_kxy), so sigma(xi) = int D t - int S u.
  Eigen::Matrix<double, 3, 2> stress_by_traction(const Eigen::Vector2d& r) const;
  Eigen::Matrix<double, 3, 2> stress_by_displacement(const Eigen::Vector2d& r, const Eigen::Vector2d& n) const;

  const ElasticConstants& constants() const { return constants_; }
  double log_scale() const { return log_scale_; }
  // U = displacement_factor() [ (3 - 4 nu) ln(R / r) I + r r^T / r^2 ].
  double displacement_factor() const { return u_factor_; }
  // On a straight element through xi, T reduces to odd_traction_factor() / (s - s_xi) [[0, -1], [1, 0]], s the
  // arc length along the element (dr/dn = 0 there and r_l n_j - r_j n_l = sign(s - s_xi) [[0, -1], [1, 0]]).
  double odd_traction_factor() const { return (1.0 - 2.0 * nu_) * t_factor_; }

 private:
  ElasticConstants constants_;
  double log_scale_;
  double nu_;
  double u_factor_;  // 1 / (8 pi mu (1 - nu))
  double t_factor_;  // 1 / (4 pi (1 - nu))
  double s_factor_;  // mu / (2 pi (1 - nu))
};

}  // namespace contact::bem
