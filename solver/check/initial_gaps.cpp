#include "initial_gaps.hpp"

#include "../mortar/contact_index.hpp"
#include "../mortar/pair.hpp"
#include "figures.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace contact::check {

namespace {

constexpr double kTouching = 1e-6;  // relative to the joint's length: the sixth significant digit of a drawing

// A body's size: its bounding box's diagonal.
double body_size(const Body& body) {
  const auto& nodes = body.mesh.nodes;
  if (nodes.empty()) return 0.0;
  Eigen::Vector2d lo = nodes.front(), hi = nodes.front();
  for (const auto& p : nodes) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  return (hi - lo).norm();
}

bool carried(mortar::NodeStatus s) { return s != mortar::NodeStatus::uncovered && s != mortar::NodeStatus::other_pair; }

PairGaps measure_pair(const Problem& problem, int k, const mortar::ContactIndex& index,
                      const std::vector<double>& sizes) {
  const mortar::PairDiscretization d = mortar::discretize_pair(problem, k, 1.0, &index);
  const ContactPair& c = problem.contacts[static_cast<size_t>(k)];
  const mesh::Mesh& slave = problem.bodies[static_cast<size_t>(c.slave_body)].mesh;
  PairGaps g;
  g.length = d.covered_length;
  g.size = std::min(sizes[static_cast<size_t>(c.slave_body)], sizes[static_cast<size_t>(c.master_body)]);
  g.tolerance = kTouching * g.length;
  for (size_t i = 0; i < d.slave_nodes.size() && i < d.initial_gap.size(); ++i) {
    const double gap = d.initial_gap[i];
    if (!carried(d.status[i]) || !std::isfinite(gap)) continue;
    const Eigen::Vector2d at = slave.nodes[static_cast<size_t>(d.slave_nodes[i])];
    if (g.nodes == 0 || gap < g.min_gap) g.min_gap = gap, g.min_at = at;
    if (g.nodes == 0 || gap > g.max_gap) g.max_gap = gap, g.max_at = at;
    ++g.nodes;
    if (gap < -g.tolerance) ++g.overlapping;
  }
  return g;
}

// "0.0001 (3.3e-04 of the joint's length 0.3, 1e-04 of the smaller body's size 1.04)"
std::string relative(double value, const PairGaps& g) {
  return number(value) + " (" + number(value / g.length) + " of the joint's length " + number(g.length) + ", " +
         number(value / g.size) + " of the smaller body's size " + number(g.size) + ")";
}

std::string overlap_text(const ContactPair& c, const PairGaps& g) {
  return "the edges of pair '" + c.name + "' overlap by up to " + relative(g.max_overlap(), g) + " at the slave node " +
         point(g.min_at) + ", over " + std::to_string(g.overlapping) + " of its " + std::to_string(g.nodes) +
         " nodes: the solver presses them apart with the force that overlap takes, before any load";
}

std::string open_text(const ContactPair& c, const PairGaps& g) {
  return "the edges of pair '" + c.name + "' do not touch: the gap is " + relative(g.min_gap, g) +
         " at its smallest, at the slave node " + point(g.min_at) + ", and " + number(g.max_gap) + " at its largest";
}

}  // namespace

std::vector<PairGaps> measure_initial_gaps(const Problem& problem, const std::function<bool()>& stop) {
  std::vector<PairGaps> out(problem.contacts.size());
  if (out.empty()) return out;
  std::vector<double> sizes;
  for (const auto& b : problem.bodies) sizes.push_back(body_size(b));
  const mortar::ContactIndex index(problem);
  for (size_t k = 0; k < out.size(); ++k) {
    if (k % 64 == 63 && stop && stop()) break;
    out[k] = measure_pair(problem, static_cast<int>(k), index, sizes);
  }
  return out;
}

std::vector<Warning> initial_gap_warnings(const Problem& problem, const std::vector<PairGaps>& gaps) {
  std::vector<Warning> out;
  for (size_t k = 0; k < gaps.size() && k < problem.contacts.size(); ++k) {
    const PairGaps& g = gaps[k];
    const ContactPair& c = problem.contacts[k];
    if (g.nodes == 0) continue;
    const std::string pointer = "/contacts/" + std::to_string(k);
    switch (c.fit) {
      case Fit::touching:
        if (g.max_overlap() > 0)
          out.push_back({pointer, overlap_text(c, g) +
                                      ". If the overlap is meant (a shrink or press fit), say \"fit\": "
                                      "\"interference\" on the pair; else correct the drawing"});
        else if (g.open())
          out.push_back({pointer, open_text(c, g) +
                                      ": the linear model closes it by a rigid motion of that size, or not at all. "
                                      "If the gap is meant (a clearance), say \"fit\": \"clearance\" on the pair; "
                                      "else draw the edges on each other"});
        break;
      case Fit::clearance:
        if (g.max_overlap() > 0)
          out.push_back({pointer, overlap_text(c, g) + ", though the pair says \"fit\": \"clearance\""});
        break;
      case Fit::interference:
        if (!(g.max_overlap() > 0))
          out.push_back(
              {pointer, "pair '" + c.name +
                            "' says \"fit\": \"interference\" but its edges do not overlap: " + "the smallest gap is " +
                            relative(g.min_gap, g) + ", at the slave node " + point(g.min_at)});
        break;
    }
  }
  return out;
}

}  // namespace contact::check
