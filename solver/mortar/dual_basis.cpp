#include "dual_basis.hpp"

#include <Eigen/LU>

namespace contact::mortar {

std::optional<DualBasis> dual_basis(const std::vector<std::pair<double, double>>& covered, double length) {
  // Exact integrals of N_i and N_i N_l over [a, b] with N_0 = 1 - xi, N_1 = xi.
  Eigen::Matrix2d Me = Eigen::Matrix2d::Zero();
  Eigen::Vector2d De = Eigen::Vector2d::Zero();
  double total = 0;
  for (const auto& [a, b] : covered) {
    if (!(b > a)) continue;
    total += b - a;
    const double i1 = (b * b - a * a) / 2, i2 = (b * b * b - a * a * a) / 3;  // integral of xi, xi^2
    De[0] += (b - a) - i1;
    De[1] += i1;
    Me(0, 0) += (b - a) - 2 * i1 + i2;
    Me(0, 1) += i1 - i2;
    Me(1, 1) += i2;
  }
  // Below this covered length the 2 x 2 mass matrix is too ill-conditioned to invert reliably.
  if (!(total > 1e-8)) return std::nullopt;
  Me(1, 0) = Me(0, 1);
  DualBasis basis;
  basis.A = De.asDiagonal() * Me.inverse();
  basis.D = length * De;
  return basis;
}

DualBasis drop_node(const DualBasis& basis, int dropped) {
  DualBasis out = basis;
  const int kept = 1 - dropped;
  out.A.row(kept) += basis.A.row(dropped);
  out.A.row(dropped).setZero();
  // integral Phi_kept' N_kept = D_kept + integral Phi_dropped N_kept = D_kept (biorthogonality); the product
  // with the dropped node's N is no longer zero, but that node carries no multiplier.
  out.D[dropped] = 0.0;
  return out;
}

}  // namespace contact::mortar
