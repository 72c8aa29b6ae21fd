#include "contact_index.hpp"

#include <algorithm>
#include <iterator>

namespace contact::mortar {

ContactIndex::ContactIndex(const Problem& problem) : as_slave(problem.bodies.size()), as_master(problem.bodies.size()) {
  for (size_t q = 0; q < problem.contacts.size(); ++q) {
    const ContactPair& c = problem.contacts[q];
    if (c.slave_body >= 0 && static_cast<size_t>(c.slave_body) < as_slave.size())
      as_slave[static_cast<size_t>(c.slave_body)].push_back(static_cast<int>(q));
    if (c.master_body >= 0 && static_cast<size_t>(c.master_body) < as_master.size())
      as_master[static_cast<size_t>(c.master_body)].push_back(static_cast<int>(q));
  }
}

std::vector<int> ContactIndex::touching(int a, int b) const {
  std::vector<int> out;
  for (const int body : {a, b}) {
    if (body < 0 || static_cast<size_t>(body) >= as_slave.size()) continue;
    const auto& s = as_slave[static_cast<size_t>(body)];
    const auto& m = as_master[static_cast<size_t>(body)];
    out.insert(out.end(), s.begin(), s.end());
    out.insert(out.end(), m.begin(), m.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace contact::mortar
