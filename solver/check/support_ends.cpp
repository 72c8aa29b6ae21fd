#include "support_ends.hpp"

#include "figures.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace contact::check {

namespace {

// How far point x lies past the end `end` of a polyline whose last segment runs from `inner` to `end`, along that
// segment's direction; 0 when its projection falls on the segment or before it.
double past_end(const Eigen::Vector2d& inner, const Eigen::Vector2d& end, const Eigen::Vector2d& x) {
  const Eigen::Vector2d d = end - inner;
  const double length = d.norm();
  if (!(length > 0)) return 0.0;
  return std::max(0.0, (x - end).dot(d / length));
}

}  // namespace

std::vector<Warning> support_end_warnings(const Problem& problem, const Step& step) {
  std::vector<Warning> out;
  for (size_t k = 0; k < problem.contacts.size() && k < step.pairs.size(); ++k) {
    const ContactPair& pair = problem.contacts[k];
    const PairField& field = step.pairs[k];
    const mesh::Mesh& master = problem.bodies[static_cast<size_t>(pair.master_body)].mesh;
    if (master.edge_set_closed(pair.master_edge)) continue;  // a loop has no end
    const std::vector<int> nodes = master.edge_set_nodes(pair.master_edge);
    if (nodes.size() < 2) continue;
    const auto at = [&](size_t i) { return master.nodes[static_cast<size_t>(nodes[i])]; };
    const Eigen::Vector2d first = at(0), second = at(1), last = at(nodes.size() - 1), before = at(nodes.size() - 2);
    const double segment = std::min((second - first).norm(), (last - before).norm());
    double total = 0.0, past = 0.0, farthest = 0.0;
    for (Eigen::Index i = 0; i < field.pressure.size(); ++i) {
      if (i >= field.weight.size() || i >= field.status.size() || field.status[i] != 0) continue;
      const double force = field.weight[i] * field.pressure[i];
      if (!(force > 0)) continue;
      total += force;
      const Eigen::Vector2d x = field.position.row(i).transpose();
      const double beyond = std::max(past_end(second, first, x), past_end(before, last, x));
      if (beyond > 1e-9 * segment) {
        past += force;
        farthest = std::max(farthest, beyond);
      }
    }
    if (!(total > 0) || past <= kForcePastTheEnd * total) continue;
    out.push_back({"/contacts/" + std::to_string(k),
                   "pair '" + field.name + "' carries " + number(100 * past / total) +
                       " % of its normal force on slave nodes past the end of its master edge '" + field.master_body +
                       "." + pair.master_edge + "' (by up to " + number(farthest) + ", the master's end segments " +
                       number(segment) +
                       " long): the dual mortar puts a multiplier's force at its node, so there the answer leans on "
                       "support that is not there (a block overhanging its support's edge can stand). Refine both "
                       "edges there to segments well under " +
                       number(farthest) + ", or end the slave edge where the master ends"});
  }
  return out;
}

}  // namespace contact::check
