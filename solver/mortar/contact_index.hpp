// The contact pairs that touch each body, for the mortar discretization's questions about a pair's neighbours
// (which pairs share its surface, which other contact edges meet its slave edge's ends): answered from the bodies'
// own pairs instead of every pair of the job. A wall of 4,129 bricks has 12,192 pairs; asked of every pair, each
// question went over all 12,192 (150 million string and index comparisons for the wall).
#pragma once

#include "contact/problem.hpp"

#include <vector>

namespace contact::mortar {

struct ContactIndex {
  // Per body: the pairs it is the slave of, and the pairs it is the master of, in the job's order.
  std::vector<std::vector<int>> as_slave, as_master;

  ContactIndex() = default;
  explicit ContactIndex(const Problem& problem);

  // The pairs with a or b as slave or master (each once), in the job's order.
  std::vector<int> touching(int a, int b) const;
};

}  // namespace contact::mortar
