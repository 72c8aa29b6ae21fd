#include "load_steps.hpp"

#include "friction_policy.hpp"

#include <algorithm>
#include <cmath>

namespace contact::ddm {

namespace {

// A frictional step that does not converge is cut: its increment is halved (at most policy::LoadStepCuts::max_cuts
// times, down to 1/32 of the step) and the sub-steps are solved and accepted in turn from the last state that held.
// Why: friction is path dependent and the semismooth Newton's start is the previous state; near the limit of what
// friction holds (bricks at the heel of a sheared wall whose bed joints slip above and below) a whole step's increment
// can leave the Newton in sets that hold no answer, while halves of it, each from an answer, converge. The sub-steps
// follow the load path more closely; they are not output steps (the step's result is its last sub-step's).
bool may_cut(const ContactSystem& system, const MethodOutcome& outcome, const RunFrame& frame) {
  // Not: frictionless steps (path independent: a cut solves the same problem), a statics refusal (the loads of the
  // step's end are refused whatever the path) or a cancel.
  return system.has_friction() && !outcome.converged && !outcome.refused &&
         outcome.stop_reason != StopReason::cancelled && !frame.stop_requested();
}

// Whether the step's solve starts from rest with every joint closed and no gap: the first step (its loads grow
// from zero in proportion), nothing accepted before it, every pair's initial gap exactly zero. The incremental
// Coulomb problem is then positively homogeneous in the load: the answer at t L is t times the answer at L, and
// the Newton's iterates are too (measured: a cut repeated the same sequence, scaled), so a cut would only solve
// the same failing problem again (an 8 x 8 wall with mu = 0.05: five cuts, 46 s, to fail as the first try did).
bool homogeneous_from_rest(const ContactSystem& system, size_t k, double done) {
  if (k != 0 || done != 0.0) return false;
  // "No gap" up to round-off: edges drawn on each other at an angle (an arch's radial joints) have nodal gaps of
  // 1e-17 that are none.
  for (const auto& pair : system.pairs())
    for (Eigen::Index r = 0; r < pair.gap0.size(); ++r)
      if (std::abs(pair.gap0[r]) > 1e-12 * pair.covered_length * std::max(pair.area[r], 0.0)) return false;
  return true;
}

}  // namespace

Step step_of(const ContactSystem& system, const MethodOutcome& outcome, const RunState& state) {
  return outcome.z.empty() ? system.fields(outcome.u, outcome.iterations, state)
                           : system.fields(outcome.u, outcome.z, outcome.iterations, state, &outcome.rigid_amplitudes,
                                           outcome.q.empty() ? nullptr : &outcome.q);
}

HeldPath run_load_steps(const ContactSystem& system, const std::vector<double>& factors, RunFrame& frame,
                        ContactMethod& method, StepLog& steps) {
  MethodOutcome& total = frame.outcome();
  RunState& state = frame.state();
  Displacements warm;
  HeldPath path;
  const auto held = [&] {  // (before the slip origins move on to it)
    path.before = std::move(path.last.u);
    path.last = total;
    path.last_state = state;
  };
  for (size_t k = 0; k < factors.size(); ++k) {
    const double previous = k == 0 ? 0.0 : factors[k - 1];
    double done = 0.0, increment = 1.0;
    int cuts = 0, sub_steps = 0;
    bool not_cut = false;
    auto announce = [&](LoadStepReport::Kind kind, double reached, double next, int iterations) {
      if (factors.size() == 1 && kind == LoadStepReport::Kind::held && reached == 1.0) return;  // one plain solve
      LoadStepReport r;
      r.kind = kind;
      r.step = static_cast<int>(k) + 1;
      r.steps = static_cast<int>(factors.size());
      r.fraction = reached;
      r.next = next;
      r.load_factor = previous + reached * (factors[k] - previous);
      r.iterations = iterations;
      frame.report(r);
    };
    while (true) {
      const double t = std::min(1.0, done + increment);
      state.load = fem::LoadPoint{k, previous, factors[k], t};
      const int before = total.iterations;
      frame.nested(warm.empty() ? nullptr : &warm, InnerMarks{},
                   [&](RunFrame& inner) { run_enforced(system, inner, method); });
      if (total.converged) announce(LoadStepReport::Kind::held, t, 0.0, total.iterations - before);
      if (total.converged) held();
      if (total.converged && t < 1.0) {  // a sub-step held: its state is the next one's start
        state.slip_origin = system.tangential_jumps(total.u);
        warm = total.u;
        done = t;
        ++sub_steps;
        continue;
      }
      if (total.converged || cuts == policy::kFrictionPolicy.cuts.max_cuts || !may_cut(system, total, frame)) break;
      if (homogeneous_from_rest(system, k, done)) {
        not_cut = true;
        break;
      }
      increment *= 0.5;
      ++cuts;
      announce(LoadStepReport::Kind::cut, done, std::min(1.0, done + increment), total.iterations - before);
    }
    std::string prefix = factors.size() == 1
                             ? std::string()
                             : "load step " + std::to_string(k + 1) + " of " + std::to_string(factors.size());
    if (cuts > 0)
      prefix += std::string(prefix.empty() ? "" : " ") + "(cut " + std::to_string(cuts) +
                " times: " + std::to_string(sub_steps + (total.converged ? 1 : 0)) + " sub-steps held, the last at " +
                std::to_string(static_cast<int>(100 * (total.converged ? 1.0 : done) + 0.5)) + " % of the step)";
    if (not_cut)
      prefix += std::string(prefix.empty() ? "" : " ") +
                "(not cut: from rest with every joint closed, a smaller increment is the same problem scaled)";
    if (!prefix.empty()) total.message = prefix + ": " + total.message;
    if (total.u.empty()) return path;
    Step step = step_of(system, total, state);
    step.index = static_cast<int>(k);
    step.load_factor = state.load.value();  // factors[k], or where a cut step failed the fraction tried
    step.converged = total.converged;
    steps.push_back(std::move(step));
    if (!total.converged) return path;
    state.slip_origin = system.tangential_jumps(total.u);  // friction: the next step's slip is measured from here
    warm = total.u;
  }
  return path;
}

}  // namespace contact::ddm
