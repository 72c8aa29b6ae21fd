#include "contact_extent.hpp"

#include <algorithm>

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

}  // namespace

ContactExtent contact_extent(const Eigen::VectorXd& arc, const Eigen::VectorXd& pressure) {
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
