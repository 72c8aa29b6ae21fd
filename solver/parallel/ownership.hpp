// Which process owns which body when the bodies are spread over several processes (MPI ranks, solver/mpi/).
#pragma once

#include "contact/problem.hpp"

#include <vector>

namespace contact::parallel {

// Owner rank of every body, for `ranks` processes: balanced by degrees of freedom (largest body first, each to
// the least loaded rank), and a body goes to a rank that already holds one of its contact partners when that
// keeps the rank within 5 % of the mean load. The same on every rank (no randomness, ties by body index).
// More ranks than bodies leaves the extra ranks without bodies.
std::vector<int> assign_bodies(const Problem& problem, int ranks);

}  // namespace contact::parallel
