// The relaxed interface fixed point shared by the Neumann and Robin schemes:
//   u~ = F(u)   (every body solved once, independently, in parallel)
//   u  <- gamma u~ + (1 - gamma) u                          (paper (17); acceleration "none")
//   u  <- Anderson mixing of the last iterates               (acceleration "anderson")
// with gamma fixed, or "auto": estimated from the largest eigenvalue of F's Jacobian (power iterations), and
// halved (from the best iterate) when the residual keeps growing.
#pragma once

#include "method.hpp"

#include <string>

namespace contact::ddm {

class BodyMap {
 public:
  virtual ~BodyMap() = default;
  // u~ = F(u): one solve per body, in parallel.
  virtual Displacements apply(const Displacements& u) = 0;
  // F's Jacobian with every contact node in contact, applied to du (one homogeneous solve per body). Its
  // spectral radius bounds the safe relaxation.
  virtual Displacements linear_response(const Displacements& du) = 0;
  // Factorisations done by the map itself (Robin refactorises when the active set changes).
  virtual int factorizations() const { return 0; }
};

// The iteration's start: the frame's warm start if any, else the settings' initial guess (zero, or the
// elastic-layer model: 2 solves per body, added to `solves`).
Displacements initial_iterate(const ContactSystem& system, const RunFrame& frame, int& solves);

// Runs the iteration from u0 with the settings' gamma (or auto), acceleration, criterion and limits.
// Builds the frame's outcome.
void run_fixed_point(const ContactSystem& system, RunFrame& frame, BodyMap& map, Displacements u0);

// Spectral radius of the map's Jacobian (all contact points active) by power iterations on the contact-zone
// normal displacements; `solves` is increased by the solves per body spent.
double estimate_spectral_radius(const ContactSystem& system, BodyMap& map, int iterations, int& solves);

// The Neumann map of paper (16): each body with the penalty tractions of u, under the loads of the state's load
// point and the penalty shifted by its multipliers.
class NeumannMap final : public BodyMap {
 public:
  NeumannMap(const ContactSystem& system, const RunState& state, parallel::TaskRunner& runner)
      : system_(system), state_(state), runner_(runner) {}
  Displacements apply(const Displacements& u) override;
  Displacements linear_response(const Displacements& du) override;

 private:
  const ContactSystem& system_;
  const RunState& state_;
  parallel::TaskRunner& runner_;
};

// Pressures of every pair's contact nodes for an interface perturbation du with all nodes in contact:
// dz = -(Gm du_m - Gs du_s) / (theta D).
Pressures linear_pressures(const ContactSystem& system, const Displacements& du);

}  // namespace contact::ddm
