// One contact pair discretised by the dual mortar method on fixed meshes (docs/algorithm.md, "Contact").
//
// Unknowns of the contact: one multiplier per contact node (a slave node that carries one), the nodal contact
// pressure z_r >= 0 (positive in compression, the paper's sigma_n = -pressure). The pressure field is
// lambda = sum_r z_r Phi_r with the dual shape functions Phi_r (dual_basis.hpp), acting along the normal of the
// slave segment it sits on.
//
// Linearised kinematics (paper section 2): the weighted gap of row r,
//   g_r = integral over the slave edge of Phi_r (x' - x) . n_k   (+ Phi_r times the job's analytic gap),
// is affine in the displacements: g = gap0 + Gm u_master - Gs u_slave, where
//   Gs(r, slave node i)  = sum_k n_k integral_k Phi_r N_i       (= D_r nu_r at i = r; others only at dropped nodes)
//   Gm(r, master node j) = sum_k n_k integral_k Phi_r N'_j      (n_k M_rj summed over the slave segments k),
// and D_r = integral Phi_r N_r. The nodal gap g_r / area_r has the units of length.
// The contact forces are  f_slave = -Gs^T z,  f_master = Gm^T z:  since the master shape functions sum to one,
// sum_j M_rj = D_r segment by segment, so the forces balance exactly on any pair of meshes.
// Contact conditions per row: z_r >= 0, g_r >= 0, z_r g_r = 0 (exact), or the paper's penalty in nodal form
// z_r = max(0, -(g_r / area_r) / theta).
//
// Friction (docs/algorithm.md, "Friction"): one tangential multiplier q_r per contact node on the same dual basis,
// acting along the row's tangent tau_r (its normal turned a quarter anticlockwise). The weighted tangential jump
//   w_r = integral Phi_r (u' - u) . tau_r  =  Tm u_master - Ts u_slave,
//   Ts(r, slave node i) = tau_r integral Phi_r N_i,   Tm(r, master node j) = tau_r M_rj,
// has the structure of the weighted gap, and the forces are f_slave = -Ts^T q, f_master = Tm^T q (balanced
// exactly, as the normal ones). So q is the tangential traction the slave exerts on the master, and the traction
// on the slave along tau is t = -q. Friction acts on increments: the slip of a load step is w - w_origin, with
// w_origin the jump at the end of the previous step (run state: ddm/run_state.hpp).
#pragma once

#include "contact/problem.hpp"
#include "contact_index.hpp"

#include <Eigen/SparseCore>

#include <string>
#include <vector>

namespace contact::mortar {

using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Whether a slave node carries a multiplier, and why not: not opposite the master, a crosspoint (its normal
// displacement prescribed), barely covered by the master, inside a multiplier segment (coarse-grained
// multipliers: the slave is finer than the master there), or carried by another pair of its group (pair_group.hpp:
// the node lies opposite the other pair's master edge, or at the end its slave edge shares with the other's).
enum class NodeStatus { contact = 0, uncovered = 1, crosspoint = 2, barely_covered = 3, inner = 4, other_pair = 5 };

struct PairDiscretization {
  std::string name;
  int slave_body = -1, master_body = -1;
  double theta = 0.0;  // penalty parameter (used by the penalty and augmented-Lagrangian enforcement)

  // Every slave node, in order along the slave edge. A closed slave edge (mesh::Mesh::edge_set_closed) lists each
  // node once, from the loop's start, and has no ends: its last segment joins the last node to the first, and the
  // start is a multiplier node between the last multiplier segment and the first like any other.
  std::vector<int> slave_nodes;
  // Positions (in slave_nodes) of the nodes that bound multiplier segments, the first and the last always among
  // them; on a closed slave edge the last is slave_nodes.size(), the start again.
  std::vector<size_t> multiplier_nodes;
  std::vector<std::vector<std::pair<int, double>>> node_from_rows;  // per slave node: (row, weight) giving its value
  Eigen::VectorXd node_arc;        // arc length along the slave polyline from its first node (a loop's start)
  bool closed = false;             // the slave edge is a closed loop
  double loop_length = 0.0;        // a closed slave edge's length, its closing segment included (0 if open)
  std::vector<NodeStatus> status;  // per slave node
  std::vector<int> row_of_node;    // per slave node: its row, or -1
  // Per slave node: the initial gap at the node itself (geometric, on the edges' true curves, plus the analytic gap;
  // negative: the edges overlap there), measured along the slave's normal to the master; NaN where no side of the
  // master lies opposite. The pointwise value the drawing gives, for the model checks (check/initial_gaps.hpp); the
  // solver uses the weighted gaps (gap0).
  std::vector<double> initial_gap;

  // One row per contact node.
  std::vector<int> node_of_row;  // row -> index into slave_nodes
  // Per row: its friction row is dropped (q = 0 there), at a corner where the slave edge meets another contact
  // edge of its body and friction would tie three bodies in a loop (pair.cpp, slave_corners).
  std::vector<char> tangential_dropped;
  Eigen::VectorXd D;                    // D_r = integral Phi_r N_r (length x thickness): the diagonal mortar matrix
  Eigen::VectorXd area;                 // integral Phi_r = sum_j M_rj: the row's share of the surface. Equal to D_r
                                        // except next to a dropped node (Phi_r then also covers the neighbour's part)
  Eigen::VectorXd gap0;                 // weighted initial gap (geometric + analytic), length^2 x thickness
  std::vector<Eigen::Vector2d> normal;  // unit normal of row r (direction of D_r nu_r): for reports
  SparseRows Gs;                        // rows x slave dofs
  SparseRows Gm;                        // rows x master dofs
  std::vector<int> master_nodes;        // the master edge's nodes in order (a closed one's each once, from its start);
                                        // in a group of pairs (pair_group.hpp) the group's master chain, all its edges
  SparseRows M;                         // rows x master_nodes (scalar mortar matrix, summed over segments)
  double covered_length = 0.0;          // length of the slave edge opposite the master edge (this pair's pieces)

  // Friction (empty operators when the pair is frictionless).
  FrictionSpec friction;
  std::vector<Eigen::Vector2d> tangent;  // per row: tau_r
  SparseRows Ts, Tm;                     // rows x slave dofs, rows x master dofs
  bool has_friction() const { return friction.active() && Ts.rows() == n_rows(); }
  // w = Tm u_master - Ts u_slave (weighted; / area gives the master's tangential displacement relative to the
  // slave's, a length).
  Eigen::VectorXd weighted_jump(const Eigen::VectorXd& us, const Eigen::VectorXd& um) const {
    return Tm * um - Ts * us;
  }
  // The resultant of the tangential forces on the slave, -Ts^T q summed by component.
  Eigen::Vector2d tangential_resultant(const Eigen::VectorXd& q) const;
  // Per row: 1 where the node is in contact (z > 0) and its tangential multiplier is below the friction bound.
  Eigen::VectorXi sticking(const Eigen::VectorXd& z, const Eigen::VectorXd& q) const;
  // Adds the tangential forces of multipliers q: fs -= Ts^T q, fm += Tm^T q.
  void add_tangential_forces(const Eigen::VectorXd& q, Eigen::VectorXd& fs, Eigen::VectorXd& fm) const;

  int n_rows() const { return static_cast<int>(D.size()); }
  Eigen::VectorXd weighted_gap(const Eigen::VectorXd& us, const Eigen::VectorXd& um) const {
    return gap0 + Gm * um - Gs * us;
  }
  // Weighted gap / area: a length (negative = penetration); the node's value for a gap linear along the slave
  // edge, a mean with the dropped neighbour next to one, and the constant for a constant gap.
  Eigen::VectorXd nodal_gap(const Eigen::VectorXd& us, const Eigen::VectorXd& um) const {
    return weighted_gap(us, um).cwiseQuotient(area);
  }
  // The penalty pressures of nodal gaps g: max(0, lambda - g / theta), with the augmented-Lagrangian multipliers
  // lambda per row (null: none; ddm/run_state.hpp).
  Eigen::VectorXd penalty_pressure(const Eigen::VectorXd& nodal_gaps, const Eigen::VectorXd* multipliers) const;
  // Adds the contact forces of row pressures z: fs -= Gs^T z, fm += Gm^T z.
  void add_forces(const Eigen::VectorXd& z, Eigen::VectorXd& fs, Eigen::VectorXd& fm) const;
  // Total normal force sum_r area_r z_r (the integral of the pressure field; per unit thickness in plane strain).
  double total_force(const Eigen::VectorXd& z) const { return area.dot(z); }
  // The resultant force vector on the slave for pressures z: the x and y sums of its nodal forces -Gs^T z.
  Eigen::Vector2d resultant(const Eigen::VectorXd& z) const;
  // Row values at every slave node: a multiplier node's own, inside a multiplier segment the linear
  // interpolation of its ends (`fill` where no row reaches a node).
  Eigen::VectorXd to_nodes(const Eigen::VectorXd& rows, double fill) const;
  // Row values at the multiplier nodes only (`fill` elsewhere): for per-row quantities such as the weights.
  Eigen::VectorXd rows_at_nodes(const Eigen::VectorXd& rows, double fill) const;
};

// theta of the pair: PenaltySpec::theta if given, else c * length / E_pair (see PenaltySpec). Also returns the
// extents of the two bodies along the pair's mean normal (the "layer heights" of the elastic-layer model).
struct PenaltyChoice {
  double theta = 0.0;
  double length = 0.0;
  double E_pair = 0.0;
  double slave_height = 0.0, master_height = 0.0;
};
PenaltyChoice choose_penalty(const Problem& problem, int pair_index);

// A slave node whose covered part of its support is below this fraction of the support carries no multiplier.
constexpr double kDropCoverage = 1e-3;

// Builds the mortar discretisation of pair `pair_index` on the bodies' current meshes. `index`: the problem's pairs
// by body (made here when null; a caller discretizing every pair makes it once).
PairDiscretization discretize_pair(const Problem& problem, int pair_index, double theta,
                                   const ContactIndex* index = nullptr);

}  // namespace contact::mortar
