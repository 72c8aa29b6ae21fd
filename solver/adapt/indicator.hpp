// Error indicators per cell and marking (paper section 3; docs/algorithm.md, "h-adaptivity").
//
// Both indicators compare the FE stresses sigma_F with a reference field sigma_R, ||s||_D = sqrt(int_D s_ij s_ij)
// (in-plane components: sxx^2 + syy^2 + 2 sxy^2; the 2x2 Gauss rule of a quadrilateral, the three-point rule of
// degree 2 of a triangle: fem/element.hpp), normalised
//   rms:  eta(e) = ( ||sigma_R - sigma_F||_e / sqrt|e| ) / ( ||sigma_R||_Omega / sqrt|Omega| )   (default)
//   area: eta(e) = ( ||sigma_R - sigma_F||_e / |e| ) / ( ||sigma_R||_Omega / |Omega| )   (the paper, as printed)
// The printed form divides an L2 norm by an area, so it scales like 1/sqrt|e|: for Q1 and P1 (stress error O(h)) it
// does not fall under refinement, and on seed_layers it marks almost every cell at every step. The rms form
// is the same comparison made scale-consistent (RMS error over the cell against RMS stress over the body).
//  * fem_bem: sigma_R = sigma_B, the boundary-element stresses of the same body problem (same prescribed
//    displacements, tractions and the current contact traction) on the boundary mesh the FE mesh induces.
//  * zz: sigma_R = sigma*, the nodally recovered FE stresses (Zienkiewicz-Zhu) interpolated in each element.
#pragma once

#include "../fem/body_solver.hpp"
#include "contact/problem.hpp"

#include <functional>
#include <string>
#include <vector>

namespace contact::adapt {

struct IndicatorResult {
  Eigen::VectorXd eta;          // per cell
  std::string note;             // e.g. why fem_bem fell back to zz
  double seconds = 0.0;         // time spent (BEM solve and interior evaluations for fem_bem)
  double error2 = 0.0;          // ||sigma_R - sigma_F||^2 over the body (the global estimate's numerator)
  double reference2 = 0.0;      // ||sigma_R||^2 over the body
  Eigen::VectorXd error2_cell;  // ||sigma_R - sigma_F||^2 per cell (unnormalised: the goal weights' primal factor)
  bool cancelled = false;       // the estimate was stopped by `cancelled` (eta is then empty)
  // fem_bem only: the FE displacements (all dofs) with the boundary nodes' replaced by the boundary-element
  // solution's, the body's response to the same data without the FE interior (pressure_estimate.hpp); empty
  // for zz and where fem_bem fell back to zz.
  Eigen::VectorXd bem_displacement;
};

// Zienkiewicz-Zhu recovery indicator of body displacements u (all dofs).
IndicatorResult zz_indicator(const Body& body, const fem::BodySolver& solver, const Eigen::VectorXd& u,
                             Normalization normalization = Normalization::rms);

// The paper's FEM-BEM indicator. contact_load: the body's contact forces (all dofs) of the current iterate,
// turned into boundary tractions by lumping over the boundary sides; the body's own loads are taken at `at`. Falls back
// to zz (with a note) where the BEM cannot be set up (a body with a hole: its boundary is not one closed polygon).
// Rigid motions the body's edge conditions leave free are fixed by the FE displacement on a few sides (indicator.cpp,
// pin_rigid_motions). `cancelled` is polled inside the boundary-element work (between blocks and GMRES iterations of
// the hierarchical path): true stops it and returns a result with cancelled set.
IndicatorResult fem_bem_indicator(const Body& body, const Model& model, const fem::BodySolver& solver,
                                  const Eigen::VectorXd& u, const Eigen::VectorXd& contact_load,
                                  const fem::LoadPoint& at = {}, Normalization normalization = Normalization::rms,
                                  const std::function<bool()>& cancelled = {});

struct Marking {
  std::vector<int> cells;  // to refine (cells over delta that max_level, max_dofs and the grading leave refinable)
  bool dof_limit_hit = false;
  bool level_limit_hit = false;
  int graded_out = 0;  // cells over delta left alone because `graded` says they are fine enough for the contact
};

// Cells with eta > delta below max_level and not `graded` (per cell; empty: none); if refining them all would
// take the body above max_dofs (counted as 2 x nodes, an upper bound on its unknowns), only the largest-eta cells
// that fit are kept.
Marking mark(const mesh::Mesh& mesh, const Eigen::VectorXd& eta, double delta, int max_level, long max_dofs,
             const std::vector<char>& graded = {});

// The boundary of a mesh as one closed counter-clockwise loop of nodes (hanging nodes are interior). Empty if
// the boundary is not a single loop.
std::vector<int> boundary_loop(const mesh::Mesh& mesh);

}  // namespace contact::adapt
