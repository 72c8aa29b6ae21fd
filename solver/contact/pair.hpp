// One contact pair discretised on fixed meshes: the slave edge S_1 is split at the projections of the master
// nodes (segment-to-segment), each piece carries Gauss points, and every Gauss point x is projected onto the
// master polyline S_2 (x' the closest point, n the master's outward normal there).
//
// Linearised kinematics (paper section 2, n_1(x) ~ -n_2(x') = -n): the normal gap after deformation is
//   g(x) = d(x) - u_1n(x) - u_2n(x') = d(x) + n . u_1(x) - n . u_2(x'),
// with d the initial gap (geometric (x - x') . n plus the job's analytic terms). Penalty (paper (11)):
// contact pressure p = max(0, -g) / theta, positive in compression (the paper's sigma_n = -p). The forces on
// the bodies are f_1 = G_s^T W p (pushing the slave along +n) and f_2 = -G_m^T W p: equal and opposite, as in
// the weak form (12). Everything here is linear algebra on these operators, so the DDM, the monolithic
// solver and the interface methods share exactly the same discrete problem.
#pragma once

#include "../problem.hpp"

#include <Eigen/SparseCore>

#include <optional>
#include <string>
#include <vector>

namespace contact::interface {

// The closest point of a boundary polyline (nodes in order along the edge) to x.
struct Projection {
  int segment = -1;   // index of the segment (between nodes segment and segment + 1)
  double t = 0.0;     // parameter along the segment, in [0, 1]
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();  // outward normal of the body owning the polyline
};

// Nodes' coordinates in order along the edge, and whether the edge runs counter-clockwise around its body
// (edge sets do: the body lies to the left, so the outward normal of a segment with direction e is (e_y, -e_x)).
// Returns nullopt when the foot of the perpendicular falls outside the polyline (x has no partner).
std::optional<Projection> project(const std::vector<Eigen::Vector2d>& polyline, const Eigen::Vector2d& x);

struct PairDiscretization {
  std::string name;
  int slave_body = -1, master_body = -1;
  double theta = 0.0;

  // Gauss points on the slave edge.
  std::vector<Eigen::Vector2d> point;
  std::vector<Eigen::Vector2d> normal;  // master outward normal at the projection
  Eigen::VectorXd weight;               // quadrature weight (length x thickness); 0 where no master point
  Eigen::VectorXd gap;                  // initial gap d
  Eigen::VectorXd arc;                  // arc length along the slave edge
  Eigen::SparseMatrix<double, Eigen::RowMajor> Gs;  // rows: n . u_slave(x_q)    (Q x slave dofs)
  Eigen::SparseMatrix<double, Eigen::RowMajor> Gm;  // rows: n . u_master(x'_q)  (Q x master dofs)

  // The same evaluated at the slave edge's nodes (reporting, and the paper's stopping test over FE nodes).
  std::vector<int> slave_nodes;
  Eigen::VectorXd node_arc, node_gap;
  Eigen::VectorXi node_has_master;      // 0 where the node's projection falls outside the master edge
  Eigen::SparseMatrix<double, Eigen::RowMajor> Hs, Hm;

  // Augmented Lagrangian multipliers (contact pressure estimates) at the Gauss points; empty for the pure
  // penalty method. With them the pressure is max(0, lambda - g / theta), the penalty pressure of the shifted
  // gap d - theta lambda (effective_gap).
  Eigen::VectorXd multiplier;
  // Per slave node: Gauss points and weights that extrapolate a Gauss-point field linearly to the node
  // (averaged over the node's one or two adjacent pieces).
  std::vector<std::vector<std::pair<int, double>>> node_from_gauss;

  int n_points() const { return static_cast<int>(weight.size()); }
  // g at the Gauss points for body displacements us (slave) and um (master), all dofs: the physical gap.
  Eigen::VectorXd normal_gap(const Eigen::VectorXd& us, const Eigen::VectorXd& um) const { return gap + Gs * us - Gm * um; }
  Eigen::VectorXd node_normal_gap(const Eigen::VectorXd& us, const Eigen::VectorXd& um) const {
    return node_gap + Hs * us - Hm * um;
  }
  // The gap the penalty acts on: d - theta lambda (d without multipliers).
  Eigen::VectorXd effective_gap() const { return multiplier.size() ? Eigen::VectorXd(gap - theta * multiplier) : gap; }
  // Contact pressure at the Gauss points from the physical gap: max(0, lambda - g / theta) (0 without master).
  Eigen::VectorXd pressure(const Eigen::VectorXd& normal_gap_values) const;
  // The pressure at the slave nodes (0 where a node has no master point): the Gauss-point pressures, which
  // the force integrates, extrapolated linearly to the nodes. Not the penalty formula with the nodes' own gaps:
  // an analytic gap is not linear between Gauss points, and with a small theta (or multipliers) the nodes of a
  // convex gap then report no contact where the Gauss points carry it.
  // node_normal_gap_values is used only for its size (kept for callers that have it at hand).
  Eigen::VectorXd node_pressure(const Eigen::VectorXd& node_normal_gap_values, const Eigen::VectorXd& gauss_pressure) const;
  // Adds the contact forces of pressures p at the Gauss points: fs += Gs^T W p, fm -= Gm^T W p.
  void add_forces(const Eigen::VectorXd& p, Eigen::VectorXd& fs, Eigen::VectorXd& fm) const;
  double total_force(const Eigen::VectorXd& p) const { return weight.dot(p); }
};

// theta of the pair: PenaltySpec::theta if given, else c * length / E_pair (see PenaltySpec). Also returns
// the extents of the two bodies along the pair's mean normal (the "layer heights" of the elastic-layer model).
struct PenaltyChoice {
  double theta = 0.0;
  double length = 0.0;
  double E_pair = 0.0;
  double slave_height = 0.0, master_height = 0.0;
};
PenaltyChoice choose_penalty(const Problem& problem, int pair_index);

// Builds the discretisation of pair `pair_index` of the problem on the bodies' current meshes.
PairDiscretization discretize_pair(const Problem& problem, int pair_index, double theta);

}  // namespace contact::interface
