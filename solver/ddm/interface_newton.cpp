#include "interface_newton.hpp"

#include "active_set.hpp"

#include <sstream>

namespace contact::ddm {

std::string InterfaceNewton::unheld_bodies(const std::vector<Eigen::Index>& rows) const {
  const Problem& problem = system_.problem();
  std::string text;
  for (const auto& f : problem_.floating()) {
    bool named = false;
    for (Eigen::Index row : rows) named = named || (row >= f.offset && row < f.offset + f.count);
    if (!named) continue;
    const auto& body = system_.body(f.body);
    std::string motions, pairs;
    for (const auto& m : body.rigid_mode_names()) motions += (motions.empty() ? "" : ", ") + m;
    for (const auto& c : problem.contacts)
      if (static_cast<size_t>(c.slave_body) == f.body || static_cast<size_t>(c.master_body) == f.body)
        pairs += (pairs.empty() ? "'" : ", '") + c.name + "'";
    text += (text.empty() ? "" : "; ") + ("body '" + problem.bodies[f.body].name + "' floats (" + motions +
                                          " free) and no contact holds it: its contact" +
                                          (pairs.find(',') != std::string::npos ? "s " : " ") + pairs +
                                          " would have to pull (the loads move it away), or it is open at the solution;"
                                          " give it displacement conditions that hold it, or load it towards its contacts");
  }
  return text.empty() ? "the contact nodes in contact do not hold the floating bodies" : text;
}

std::vector<Eigen::VectorXd> InterfaceNewton::rigid_amplitudes(const Eigen::VectorXd& alpha) const {
  std::vector<Eigen::VectorXd> out(system_.n_bodies());
  if (alpha.size() != problem_.equilibrium().G.rows()) return out;  // (G does not depend on the load)
  for (const auto& f : problem_.floating()) out[f.body] = alpha.segment(f.offset, f.count);
  return out;
}

MethodOutcome InterfaceNewton::solve(const SolverSettings& settings, RunContext& context) {
  MethodOutcome out;
  const auto& pairs = system_.pairs();
  const InterfaceProblem& ip = problem_;
  const Eigen::Index m = ip.size();

  // H = F (+ theta D for the penalty), g = g_free (- theta D lambda under the augmented Lagrangian).
  Eigen::MatrixXd H = ip.compliance();
  Eigen::VectorXd g = ip.free_gap();
  if (settings.enforcement != Enforcement::exact) {
    for (size_t k = 0; k < pairs.size(); ++k) {
      const auto& pair = pairs[k];
      for (Eigen::Index r = 0; r < pair.n_rows(); ++r) {
        const Eigen::Index i = ip.offset(k) + r;
        H(i, i) += pair.theta * pair.area[r];
        if (pair.multiplier.size() == pair.n_rows()) g[i] -= pair.theta * pair.area[r] * pair.multiplier[r];
      }
    }
  }

  const Equalities equilibrium = ip.equilibrium();
  // The first active set: from the previous solve (augmented-Lagrangian updates), else from the nested coarse
  // solves (active_set.hpp), which keeps the number of steps independent of the mesh.
  std::string first_note;
  Eigen::VectorXd z0 = last_z_;
  if (z0.size() != m) {
    std::vector<int> line(static_cast<size_t>(m));
    Eigen::VectorXd position(m);
    for (size_t k = 0; k < pairs.size(); ++k)
      for (Eigen::Index r = 0; r < pairs[k].n_rows(); ++r) {
        line[static_cast<size_t>(ip.offset(k) + r)] = static_cast<int>(k);
        position[ip.offset(k) + r] = pairs[k].node_arc[pairs[k].node_of_row[static_cast<size_t>(r)]];
      }
    std::vector<std::pair<Eigen::Index, int>> levels;
    z0 = nested_initial_guess(H, g, line, position, equilibrium, &levels);
    if (!levels.empty()) {
      std::ostringstream os;
      os << "first active set from coarse solves:";
      for (const auto& [size, steps] : levels) os << " " << size << " nodes/" << steps << " steps";
      first_note = os.str();
    }
  }

  std::vector<std::vector<char>> previous_active;
  const Eigen::VectorXd penalty_diagonal = H.diagonal() - ip.compliance().diagonal();  // theta area (0: exact)
  const Eigen::VectorXd free_gap = ip.free_gap();
  const Eigen::VectorXd shift = g - free_gap;                                           // -theta area lambda
  auto on_step = [&](const Eigen::VectorXd& z, const Eigen::VectorXd& h, const ActiveSetStep& step) {
    // The reported gaps are the physical ones: h without the penalty's theta area z and the multipliers' shift.
    const Eigen::VectorXd gap = h - penalty_diagonal.cwiseProduct(z) - shift;
    IterationReport r = system_.report_gaps(step.step, ip.split(z), ip.split(gap.cwiseQuotient(ip.weights())), previous_active);
    r.measure = Measure::complementarity;
    r.complementarity = step.complementarity;
    r.active_set_changes = step.changes;
    if (step.step == 1) r.note = first_note;
    r.elapsed_seconds = context.elapsed();
    context.observer.on_iteration(r);
    out.history.push_back(std::move(r));
    return !context.cancel.cancelled();
  };
  const int max_steps = std::max(1, settings.max_iterations);
  const ActiveSetResult result = solve_active_set(H, g, max_steps, on_step,
                                                  z0.size() == m && z0.cwiseAbs().maxCoeff() > 0 ? &z0 : nullptr,
                                                  equilibrium);
  last_z_ = result.z;
  out.iterations = result.steps;
  if (result.cancelled) {
    out.reason = StopReason::cancelled;
    out.message = "cancelled";
  } else if (result.converged) {
    out.converged = true;
    out.reason = StopReason::converged;
    out.message = "interface Newton: " + result.message;
  } else if (!result.unrestrained.empty()) {
    out.reason = StopReason::error;
    out.message = "interface Newton: " + unheld_bodies(result.unrestrained);
    return out;
  } else {
    out.reason = result.steps >= max_steps ? StopReason::max_iterations : StopReason::error;
    out.message = "interface Newton: " + result.message;
  }
  out.z = ip.split(result.z);
  out.u = ip.displacements(result.z, result.alpha, context.runner);
  out.rigid_amplitudes = rigid_amplitudes(result.alpha);
  out.solves_per_body = 1;
  return out;
}

}  // namespace contact::ddm
