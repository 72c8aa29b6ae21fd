// Goal-oriented marking for a target on the contact pressure (issue 30, item 1; docs/algorithm.md, "Refinement for
// the pressure's target").
//
// The pressure estimate (pressure_estimate.hpp) finds the correction dz the boundary-element bodies ask for:
// G dz = -(g_B - g_F) on the active rows, the gaps' misfit g_B - g_F = B (u - u_h) being the FE bodies' error at
// the contact. Which cells cause it is a dual-weighted-residual question: for a load w on a body's contact
// surface,
//   w^T B (u - u_h) = a(u - u_h, phi) = a(u - u_h, phi - phi_h)      (Galerkin orthogonality)
//                  <= sum_K ||sigma(u - u_h)||_K ||sigma(phi - phi_h)||_K / E',
// phi the body's response to w with its prescribed displacements held at zero. With w the correction's own
// contact traction (the direction in which the pressure is wrong) each cell's term is its share of the
// correction. The primal factor is the fem_bem indicator's ||sigma_B - sigma_F||_K; the dual one the
// Zienkiewicz-Zhu estimate of phi_h's stress error; E' the body's plane modulus (a stiffer body's stress error
// moves the gaps less). Unlike the stress indicator alone, this weighs a coarse far field by how much it moves
// the contact: a body 0.2 % too stiff everywhere (the two-cylinder example's far field) asks for its far field,
// and a clamped corner's singularity that hardly moves the contact does not.
#pragma once

#include "../ddm/contact_system.hpp"
#include "../parallel/task_runner.hpp"
#include "indicator.hpp"
#include "pressure_estimate.hpp"

#include <Eigen/Core>
#include <vector>

namespace contact::adapt {

// Per adaptive body (eta[a].error2_cell not empty) and cell, the term ||sigma(u - u_h)||_K ||sigma(phi - phi_h)||_K
// / E' of the pressure correction (pe.correction, not empty), plus the contact edges' and stick-slip points'
// shares: the estimate's other parts (pe.edges and pe.stick_slip, the piecewise-linear profiles' misfit of the
// square-root ends of the pressure and of the tangential slack), which no FE error indicator sees, are given to
// the cells within the last two multiplier segments of each such point, in the proportion (edges^2 +
// stick_slip^2) / defect^2 of the correction's terms. Empty vectors for the bodies that do not adapt.
std::vector<Eigen::VectorXd> goal_indicator(const Problem& problem, const ddm::ContactSystem& system,
                                            const PressureEstimate& pe, const std::vector<IndicatorResult>& eta,
                                            parallel::TaskRunner& runner);

// Doerfler's bulk marking over all bodies: the fewest cells, largest terms first, whose terms sum to at least
// `theta` of the total. Cells of that set at max_level cannot be split: they are left out (the others are not
// replaced by more), and `level_limit_hit` says so; when they are the whole set, nothing is marked.
struct BulkMarking {
  std::vector<std::vector<int>> cells;  // per body
  bool level_limit_hit = false;
};
BulkMarking bulk_marking(const Problem& problem, const std::vector<Eigen::VectorXd>& goal, double theta, int max_level);

}  // namespace contact::adapt
