#include "ownership.hpp"

#include <algorithm>
#include <numeric>

namespace contact::parallel {

std::vector<int> assign_bodies(const Problem& problem, int ranks) {
  const size_t n = problem.bodies.size();
  std::vector<int> owner(n, 0);
  if (ranks <= 1) return owner;
  std::vector<double> weight(n);
  for (size_t a = 0; a < n; ++a) weight[a] = 2.0 * problem.bodies[a].mesh.num_nodes();
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t i, size_t j) { return weight[i] > weight[j]; });
  const double mean = std::accumulate(weight.begin(), weight.end(), 0.0) / ranks;
  std::vector<double> load(static_cast<size_t>(ranks), 0.0);
  std::fill(owner.begin(), owner.end(), -1);
  for (size_t a : order) {
    const int least = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
    int choice = least;
    double best = -1;
    for (const auto& c : problem.contacts) {
      const int other = static_cast<size_t>(c.slave_body) == a    ? c.master_body
                        : static_cast<size_t>(c.master_body) == a ? c.slave_body
                                                                  : -1;
      if (other < 0 || owner[static_cast<size_t>(other)] < 0) continue;
      const int r = owner[static_cast<size_t>(other)];
      const double after = load[static_cast<size_t>(r)] + weight[a];
      if (after <= 1.05 * mean && (best < 0 || after < best)) {
        best = after;
        choice = r;
      }
    }
    owner[a] = choice;
    load[static_cast<size_t>(choice)] += weight[a];
  }
  return owner;
}

}  // namespace contact::parallel
