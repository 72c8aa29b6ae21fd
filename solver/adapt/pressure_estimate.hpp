// An estimate of the contact pressure's error (issue 30, item 2; docs/algorithm.md, "The pressure estimate").
//
// The discrete pressure z closes the FE bodies' gaps on the active rows: g_F(z) = 0 there. The exact pressure
// closes the exact bodies' gaps. The fem_bem indicator already solves each adaptive body's boundary-element
// problem with the same data (prescribed displacements, applied tractions and the contact traction of z): its
// boundary displacements are the body's response to z without the FE interior's error. With them the gaps on
// the active rows are g_B != 0, and the pressure correction that would close them is, to first order,
//   G dz = -(g_B - g_F) on the active rows,   G = D^-1 B K^-1 B^T  (the FE bodies' contact compliance),
// solved by conjugate gradients in the D-weighted inner product (D B K^-1 B^T is symmetric), one solve per body
// and iteration. The estimate is ||dz|| / ||z||, both weighted by D (the rows' share of the surface): a
// relative L2 error of the pressure over the contact surfaces.
#pragma once

#include "../ddm/contact_system.hpp"
#include "indicator.hpp"

#include <functional>
#include <string>
#include <vector>

namespace contact::adapt {

struct PressureEstimate {
  double relative = 0.0;  // sqrt(defect^2 + edges^2 + stick_slip^2); NaN when it could not be made (see note)
  double defect = 0.0;    // ||dz||_D / ||z||_D, the pressure correction the boundary-element bodies ask for
  double edges = 0.0;     // the contact edges' square-root misfit, relative to ||z||_D (pressure_estimate.cpp)
  // With friction: the tangential traction's misfit at the stick-slip points, the same square-root model on the
  // slack (the friction bound less |q|) that rises from them into the stick zone, relative to ||z||_D.
  double stick_slip = 0.0;
  int iterations = 0;         // conjugate-gradient iterations (one solve per body each)
  ddm::Pressures correction;  // dz per pair and row (zero on the open rows); empty when there is no estimate
  // Each contact edge's share of `edges` and each stick-slip point's of `stick_slip`: where (its last node in
  // contact, or sticking), over what length (its last two multiplier segments) and its squared misfit relative to
  // ||z||_D^2 (they sum to edges^2 + stick_slip^2).
  struct EdgeShare {
    int slave_body = -1, master_body = -1;
    Eigen::Vector2d at = Eigen::Vector2d::Zero();         // the slave's last node in contact (undeformed)
    Eigen::Vector2d master_at = Eigen::Vector2d::Zero();  // the master nodes its row couples to, their mean
    double length = 0.0;
    double relative2 = 0.0;
  };
  std::vector<EdgeShare> edge_shares;
  std::string note;  // why there is none, or that the iteration stopped short
};

// z: the pressures the solve reached (per pair, per row); eta: the estimate's per-body results (bodies without
// bem_displacement keep their FE displacements: they are not estimated).
// `stop` is polled before each conjugate-gradient iteration (one solve per body): true ends it, the estimate NaN.
// q: the tangential multipliers of a frictional solve (nullptr: frictionless), for the stick-slip term.
// `at`: the load point the bodies' loads are taken at (they cancel in the compliance; the run's).
PressureEstimate pressure_estimate(const ddm::ContactSystem& system, const fem::LoadPoint& at,
                                   const ddm::Displacements& u, const ddm::Pressures& z,
                                   const std::vector<IndicatorResult>& eta, const std::function<bool()>& stop = {},
                                   const ddm::Pressures* q = nullptr);

}  // namespace contact::adapt
