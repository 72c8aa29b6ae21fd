#include "contact_extent.hpp"

#include <algorithm>
#include <vector>

namespace contact {

namespace {

// The edge beyond node j (in contact) towards node j + step (open), from nodes j and j - step.
double edge_beyond(const Eigen::VectorXd& s, const Eigen::VectorXd& p, Eigen::Index j, Eigen::Index step) {
  const Eigen::Index open = j + step, inner = j - step;
  const Eigen::Index n = s.size();
  if (open < 0 || open >= n) return s[j];
  if (inner < 0 || inner >= n || !(p[inner] > p[j]) || !(p[j] > 0)) return s[j];
  const double pj2 = p[j] * p[j], pi2 = p[inner] * p[inner];
  const double edge = s[j] + (s[j] - s[inner]) * pj2 / (pi2 - pj2);
  return std::clamp(edge, std::min(s[j], s[open]), std::max(s[j], s[open]));
}

// On a loop of length L: edge_beyond on the node positions round the loop, unwrapped about node j (a neighbour
// across the start is a loop length before or after it), the result wrapped back into [0, L).
double edge_beyond_on_loop(const Eigen::VectorXd& s, const Eigen::VectorXd& p, Eigen::Index j, Eigen::Index step,
                           double L) {
  const Eigen::Index n = s.size();
  Eigen::VectorXd ls(3), lp(3);  // inner, j, open
  for (Eigen::Index k = -1; k <= 1; ++k) {
    const Eigen::Index at = j + k * step, q = ((at % n) + n) % n;
    ls[k + 1] = s[q] + (at < 0 ? -L : at >= n ? L : 0.0);
    lp[k + 1] = p[q];
  }
  double edge = edge_beyond(ls, lp, 1, 1);
  if (edge < 0) edge += L;
  if (edge >= L) edge -= L;
  return edge;
}

// contact_extent on a closed loop of length L.
ContactExtent extent_on_loop(const Eigen::VectorXd& arc, const Eigen::VectorXd& pressure, double L) {
  ContactExtent out;
  const Eigen::Index n = pressure.size();
  std::vector<Eigen::Index> contact;
  for (Eigen::Index j = 0; j < n; ++j)
    if (pressure[j] > 0) contact.push_back(j);
  if (contact.empty()) return out;
  out.any = true;
  if (static_cast<Eigen::Index>(contact.size()) == n) {
    out.end = L;
    return out;
  }
  // The longest open stretch: between consecutive nodes in contact, round the loop.
  size_t after = 0;  // the zone starts at contact[after], just after the longest open stretch
  double longest = -1;
  for (size_t k = 0; k < contact.size(); ++k) {
    const Eigen::Index from = contact[(k + contact.size() - 1) % contact.size()], to = contact[k];
    double length = arc[to] - arc[from];
    if (length <= 0) length += L;
    if (length > longest) {
      longest = length;
      after = k;
    }
  }
  const Eigen::Index first = contact[after], last = contact[(after + contact.size() - 1) % contact.size()];
  out.begin = edge_beyond_on_loop(arc, pressure, first, -1, L);
  out.end = edge_beyond_on_loop(arc, pressure, last, +1, L);
  return out;
}

}  // namespace

ContactExtent contact_extent(const Eigen::VectorXd& arc, const Eigen::VectorXd& pressure, double loop_length) {
  if (loop_length > 0 && pressure.size() > 0) return extent_on_loop(arc, pressure, loop_length);
  ContactExtent out;
  Eigen::Index first = -1, last = -1;
  for (Eigen::Index j = 0; j < pressure.size(); ++j)
    if (pressure[j] > 0) {
      if (first < 0) first = j;
      last = j;
    }
  if (first < 0) return out;
  out.any = true;
  out.begin = edge_beyond(arc, pressure, first, -1);
  out.end = edge_beyond(arc, pressure, last, +1);
  return out;
}

}  // namespace contact
