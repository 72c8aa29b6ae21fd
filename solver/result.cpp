#include "contact/result.hpp"

#include "contact_extent.hpp"

namespace contact {

const char* to_string(StopReason r) {
  switch (r) {
    case StopReason::converged:
      return "converged";
    case StopReason::max_iterations:
      return "max_iterations";
    case StopReason::stagnation:
      return "stagnation";
    case StopReason::cancelled:
      return "cancelled";
    case StopReason::error:
      return "error";
  }
  return "error";
}

const char* to_string(Measure m) {
  switch (m) {
    case Measure::fixed_point:
      return "fixed_point";
    case Measure::complementarity:
      return "complementarity";
    case Measure::gradient:
      return "gradient";
  }
  return "fixed_point";
}

namespace {

// The length of a pair's slave edge where it is a closed loop (its closing segment, from the last node back to
// the first, included), else 0.
double loop_length(const Step& step, const PairField& p) {
  const auto n = p.arc_length.size();
  if (n < 2 || p.position.rows() != n) return 0.0;
  for (const auto& b : step.bodies)
    if (b.name == p.slave_body && b.mesh.edge_set_closed(p.slave_edge))
      return p.arc_length[n - 1] + (p.position.row(0) - p.position.row(n - 1)).norm();
  return 0.0;
}

}  // namespace

StepSummary summarize(const Step& step) {
  StepSummary s;
  s.index = step.index;
  s.iteration = step.iteration;
  s.load_factor = step.load_factor;
  s.converged = step.converged;
  for (const auto& b : step.bodies) {
    s.body_names.push_back(b.name);
    s.elements.push_back(b.mesh.num_cells());
    s.nodes.push_back(b.mesh.num_nodes());
  }
  for (const auto& p : step.pairs) {
    s.pair_names.push_back(p.name);
    s.force.push_back(p.force);
    s.tangential_force.push_back(p.tangential_force);
    // The zone this pair carries: a node another pair of its group carries (status 5) lists that pair's pressure,
    // and belongs to that pair's zone.
    Eigen::VectorXd carried = p.pressure;
    for (Eigen::Index j = 0; j < carried.size() && j < p.status.size(); ++j)
      if (p.status[j] == 5) carried[j] = 0.0;
    const ContactExtent extent = contact_extent(p.arc_length, carried, loop_length(step, p));
    s.contact_begin.push_back(extent.begin);
    s.contact_end.push_back(extent.end);
  }
  return s;
}

}  // namespace contact
