// The one vocabulary of the solver's iterative pieces: what each returns about how it stopped. GMRES (bem/), MPRGP,
// the primal-dual active set and the friction Newton (linalg/), and the interface solvers (ddm/interface/) carry a
// SolveReport beside their own results, so that a caller reads "did it converge, why did it stop, after how many,
// at what measure" in the same words whichever piece it called. The run's public RunOutcome (contact/result.hpp)
// is the same at the top, with the job's stop reasons.
#pragma once

#include <string>

namespace contact {

enum class SolveStop {
  converged,       // its stop test held
  max_iterations,  // its budget ran out first
  singular,        // a system it had to solve had no solution (the friction Newton's sets; a factorisation)
  cancelled,       // a cancel request (or a step callback) stopped it
};

struct SolveReport {
  SolveStop stop = SolveStop::max_iterations;
  long iterations = 0;   // in the piece's own unit: GMRES and MPRGP products, active-set and Newton steps, outer
                         // iterations of an interface solver
  double measure = 0.0;  // the last value of what its stop test reads (a relative residual, a projected gradient)
  std::string message;   // why, in words, where the piece says more than its stop

  bool converged() const { return stop == SolveStop::converged; }
  bool cancelled() const { return stop == SolveStop::cancelled; }
};

}  // namespace contact
