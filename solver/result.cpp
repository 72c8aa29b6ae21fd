#include "contact/result.hpp"

#include "contact_extent.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

double slave_loop_length(const Step& step, const PairField& p) {
  const auto n = p.arc_length.size();
  if (n < 2 || p.position.rows() != n) return 0.0;
  for (const auto& b : step.bodies)
    if (b.name == p.slave_body && b.mesh.edge_set_closed(p.slave_edge))
      return p.arc_length[n - 1] + (p.position.row(0) - p.position.row(n - 1)).norm();
  return 0.0;
}

StepSummary summarize(const Step& step) {
  StepSummary s;
  s.index = step.index;
  s.iteration = step.iteration;
  s.load_factor = step.load_factor;
  s.multiplier = step.multiplier;
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
    const ContactExtent extent = contact_extent(p.arc_length, carried, slave_loop_length(step, p));
    s.contact_begin.push_back(extent.begin);
    s.contact_end.push_back(extent.end);
  }
  return s;
}

JointResults joint_results(const PairField& f) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  JointResults j;
  const Eigen::Index n = f.weight.size();
  const bool friction = f.friction != "none" && f.stick.size() == n && f.tangential_traction.size() == n;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (Eigen::Index i = 0; i < n && i < f.status.size(); ++i)
    if (f.status[i] != 1 && f.status[i] != 5) {  // not opposite the master, or carried by another pair
      lo = std::min(lo, f.arc_length[i]);
      hi = std::max(hi, f.arc_length[i]);
    }
  double W = 0.0, N = 0.0, moment = 0.0, open = 0.0, slipping = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = f.weight[i], p = f.pressure[i];
    if (!(w > 0)) continue;
    W += w;
    if (p > 0) {
      N += w * p;
      moment += w * p * f.arc_length[i];
      if (friction && f.stick[i] == 0) slipping += w;
    } else {
      open += w;
    }
  }
  j.open_fraction = W > 0 ? open / W : nan;
  j.slip_fraction = friction && W > 0 ? slipping / W : nan;
  j.centre_of_pressure = N > 0 ? moment / N : nan;
  j.eccentricity = N > 0 && hi > lo ? (j.centre_of_pressure - 0.5 * (lo + hi)) / (0.5 * (hi - lo)) : nan;
  const double capacity = f.friction == "coulomb"  ? f.friction_coefficient * N
                          : f.friction == "tresca" ? f.friction_bound * W
                                                   : 0.0;
  j.friction_utilisation = capacity > 0 ? std::abs(f.tangential_force) / capacity : nan;
  return j;
}

}  // namespace contact
