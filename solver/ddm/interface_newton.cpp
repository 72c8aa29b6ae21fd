#include "interface_newton.hpp"

#include "active_set.hpp"

#include <sstream>

namespace contact::ddm {

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
    z0 = nested_initial_guess(H, g, line, position, &levels);
    if (!levels.empty()) {
      std::ostringstream os;
      os << "first active set from coarse solves:";
      for (const auto& [size, steps] : levels) os << " " << size << " nodes/" << steps << " steps";
      first_note = os.str();
    }
  }

  std::vector<std::vector<char>> previous_active;
  auto on_step = [&](const Eigen::VectorXd& z, const Eigen::VectorXd& h, const ActiveSetStep& step) {
    // The reported gaps are the physical ones: h minus the penalty's theta D z, plus the shift theta D lambda.
    Eigen::VectorXd gap = ip.free_gap() + ip.compliance() * z;
    IterationReport r = system_.report_gaps(step.step, ip.split(z), ip.split(gap.cwiseQuotient(ip.weights())), previous_active);
    (void)h;
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
  const ActiveSetResult result = solve_active_set(H, g, max_steps, on_step, z0.size() == m && z0.cwiseAbs().maxCoeff() > 0 ? &z0 : nullptr);
  last_z_ = result.z;
  out.iterations = result.steps;
  if (result.cancelled) {
    out.reason = StopReason::cancelled;
    out.message = "cancelled";
  } else if (result.converged) {
    out.converged = true;
    out.reason = StopReason::converged;
    out.message = "interface Newton: " + result.message;
  } else {
    out.reason = result.steps >= max_steps ? StopReason::max_iterations : StopReason::error;
    out.message = "interface Newton: " + result.message;
  }
  out.z = ip.split(result.z);
  out.u = ip.displacements(result.z, context.runner);
  out.solves_per_body = 1;
  return out;
}

}  // namespace contact::ddm
