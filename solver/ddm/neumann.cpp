// The paper's parallel Neumann domain decomposition, eqs. (16)-(17):
//   every body a solves  a_a(u~_a^{k+1}, v) = l_a(v) + (1/theta) int_S (d - u_1n^k - u_2n^k)^- v_an dS
//   independently (in parallel), then relaxes  u_a^{k+1} = gamma u~_a^{k+1} + (1 - gamma) u_a^k.
// Only the right-hand side changes between iterations, so each body's factorisation is reused throughout.
// The relaxation (fixed, auto, Anderson) lives in fixed_point.cpp, shared with the Robin variant.
#include "fixed_point.hpp"

namespace contact::ddm {

void run_neumann(const ContactSystem& system, RunFrame& frame) {
  int initial_solves = 0;
  Displacements u0 = initial_iterate(system, frame, initial_solves);
  NeumannMap map(system, frame.state(), frame.runner());
  run_fixed_point(system, frame, map, std::move(u0));
  frame.outcome().subdomain_solves += initial_solves;
}

}  // namespace contact::ddm
