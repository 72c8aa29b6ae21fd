// Dual (biorthogonal) Lagrange multiplier shape functions on one linear slave segment.
//
// On a segment with the linear shape functions N_0 = 1 - xi, N_1 = xi, the dual functions
// Phi_i = sum_l A(i, l) N_l satisfy  integral_P Phi_i N_l = delta_il integral_P N_l  over the part P of the
// segment that the master side covers (Wohlmuth 2000; on a partly covered segment this is the "consistent" dual
// basis of Cichosz & Bischoff 2011, used by Popp et al. 2013). With them the mortar matrix D (slave x slave) is
// diagonal, D_ii = integral_P N_i, and Phi_0 + Phi_1 = 1, so a constant pressure is represented exactly.
// On a fully covered segment A = [[2, -1], [-1, 2]].
//
// Dropping a node (a crosspoint with prescribed normal displacement, or a node the master barely covers) removes
// its multiplier; its dual function is added to the other node's on the segment (Wohlmuth's crosspoint
// modification: Phi_other + Phi_dropped, which is 1 on a fully covered segment), so the remaining multipliers
// still sum to one there and D stays diagonal for them.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <utility>
#include <vector>

namespace contact::mortar {

struct DualBasis {
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();  // Phi_i = A(i, 0) N_0 + A(i, 1) N_1
  Eigen::Vector2d D = Eigen::Vector2d::Zero();  // integral over P of N_i (times the segment length)

  double phi(int i, double xi) const { return A(i, 0) * (1 - xi) + A(i, 1) * xi; }
};

// The dual basis on a segment of length `length` whose covered part is the union of the parameter intervals
// `covered` (disjoint, inside [0, 1]). nullopt when the covered part has (numerically) no length.
std::optional<DualBasis> dual_basis(const std::vector<std::pair<double, double>>& covered, double length);

// The basis with node `dropped` (0 or 1) removed: its function is added to the other node's.
DualBasis drop_node(const DualBasis& basis, int dropped);

}  // namespace contact::mortar
