#include "contact/solve.hpp"

#include "adapt/adaptive.hpp"
#include "check/large_motion.hpp"
#include "check/support_ends.hpp"
#include "ddm/load_steps.hpp"
#include "held_bodies.hpp"
#include "limit/collapse.hpp"
#include "limit/verdict.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <limits>
#include <sstream>

namespace contact {

const char* solver_version() { return CONTACT_VERSION; }

namespace {

// Largest overlap max(0, -g) over the slave nodes of every pair.
double max_penetration(const Step& step) {
  double m = 0;
  for (const auto& p : step.pairs)
    if (p.penetration.size()) m = std::max(m, p.penetration.maxCoeff());
  return m;
}

// The monolithic reference solves the coupled system however little holds a floating body (its rigid motion
// then comes out zero, one of many solutions; MethodFacts::checks_held_bodies): a solution at which the contacts in
// contact do not hold every floating body is refused as interface Newton refuses it, with no result (the iterate left
// out of the result, output.iterate unset, is checked too: a run stopped on it is refused for that reason, not for the
// iterations).
void refuse_unheld_bodies(const Problem& problem, Result& result, const Step* dropped_iterate) {
  if (result.stop_reason != StopReason::converged && result.stop_reason != StopReason::max_iterations) return;
  std::vector<const Step*> reached;
  for (const auto& step : result.steps) reached.push_back(&step);
  if (dropped_iterate) reached.push_back(dropped_iterate);
  for (const Step* step : reached) {
    const std::string unheld = unheld_floating_bodies(problem, *step);
    if (unheld.empty()) continue;
    result.stop_reason = StopReason::error;
    result.converged = false;
    result.message = result.method + ": " + unheld;
    result.steps.clear();
    result.streamed_steps = 0;
    result.step_history.clear();
    result.kept.clear();
    return;
  }
}

// A contact only pushes: the pairs of the last step whose total normal force pulls, beyond rounding (relative to
// the largest sum of |weight x pressure| over the step's pairs), as "'name' (force -3865)"; empty if none.
std::string tensile_pairs(const Step& step) {
  double scale = 0.0;
  for (const auto& p : step.pairs)
    if (p.weight.size() == p.pressure.size())
      scale = std::max(scale, p.weight.cwiseProduct(p.pressure).cwiseAbs().sum());
  std::ostringstream os;
  for (const auto& p : step.pairs) {
    if (!(p.force < -1e-6 * scale)) continue;
    os << (os.tellp() > 0 ? ", " : "") << "'" << p.name << "' (force " << p.force << ")";
  }
  return os.str();
}

// A tensile contact force is never an answer. The solvers' answers hold p >= 0 at every contact node; an iterate
// they stopped on short of convergence may not, and the message says it is no answer. A solve that claims
// convergence on one is refused (no result): its stop test was wrong.
void refuse_tension(Result& result) {
  if (result.steps.empty() || (!result.converged && result.steps.back().converged)) return;
  const std::string pulling = tensile_pairs(result.steps.back());
  if (pulling.empty()) return;
  const std::string what = "contact " + pulling + " pulls, and a contact only pushes";
  if (!result.converged) {
    result.message += "; the last iterate is not an answer: " + what;
    return;
  }
  result.stop_reason = StopReason::error;
  result.converged = false;
  result.message = "the solve stopped on a state that is not an answer: " + what + " (" + result.message + ")";
  result.steps.clear();
  result.streamed_steps = 0;
  result.step_history.clear();
  result.kept.clear();
}

// Contact gaps are computed from the coordinates, to about 1e-16 of the model's size: displacements within a few
// hundred times that make every gap, penetration and contact force rounding (E = 1e25 under a traction of 1e-25, or
// a prescribed displacement of 1e-25, converged with contact forces 1e18 times what the load can make, and pressures
// of either sign). A step that moved the bodies by less than kResolution of the model's size, but not by nothing (no
// load: an exact zero), is refused with the figures; a linear solve without contact is exact at any scale.
constexpr double kResolution = 1e-13;

void refuse_below_resolution(const Problem& problem, Result& result) {
  if (problem.contacts.empty() || result.steps.empty() || !result.converged) return;
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const auto& body : problem.bodies)
    for (const auto& x : body.mesh.nodes) {
      low = low.cwiseMin(x);
      high = high.cwiseMax(x);
    }
  const double size = (high - low).norm();
  double moved = 0.0;
  for (const auto& step : result.steps)
    for (const auto& body : step.bodies)
      if (body.displacement.size()) moved = std::max(moved, body.displacement.cwiseAbs().maxCoeff());
  if (!(size > 0) || moved == 0.0 || moved >= kResolution * size) return;
  std::ostringstream os;
  os << "the loads move the bodies by at most " << moved << ", below what the contact geometry resolves (about "
     << kResolution << " of the model's size " << size << ", " << kResolution * size
     << "): its gaps, penetrations and contact forces would be rounding, not an answer. Scale the units (Young's "
        "moduli and loads together, e.g. MPa with N/mm) so that the loads move the bodies by more than that";
  result.stop_reason = StopReason::error;
  result.converged = false;
  result.message = os.str();
  result.steps.clear();
  result.streamed_steps = 0;
  result.step_history.clear();
  result.kept.clear();
}

// The answer's warnings after the problem's (check/large_motion.hpp: on the last step). A strict job fails on one of
// them: its steps are kept, the stop says why (a warning never changes the answer).
void add_warnings(const Problem& problem, Result& result) {
  if (result.steps.empty()) return;
  std::vector<Warning> after = check::motion_warnings(problem, result.steps.back());
  const std::vector<Warning> ends = check::support_end_warnings(problem, result.steps.back());
  after.insert(after.end(), ends.begin(), ends.end());
  result.warnings.insert(result.warnings.end(), after.begin(), after.end());
  if (!problem.strict || after.empty() || !result.converged) return;
  result.stop_reason = StopReason::error;
  result.converged = false;
  result.message = "strict: " + after.front().pointer + ": " + after.front().message +
                   (after.size() > 1 ? " (and " + std::to_string(after.size() - 1) + " more warnings)" : "") +
                   "; the solve itself converged (" + result.message + ")";
}

// What the result of a run that did not converge keeps: the steps that held and, if the job asked for it
// (OutputSettings::iterate), the last iterate flagged as not converged. Empty when nothing was solved.
std::string what_the_result_keeps(const Problem& problem, const ddm::StepLog& steps) {
  const int held = steps.held();
  const bool iterate = steps.ends_with_iterate();
  if (held == 0 && !iterate && !steps.dropped_iterate()) return "";
  const std::string kind = problem.adaptivity.enabled           ? "adaptive step"
                           : problem.loading.factors.size() > 1 ? "load step"
                                                                : "step";
  std::ostringstream os;
  // output.steps "last" keeps the fields of one step (the last that held, or the iterate in its place); every
  // step's scalars stay in /history/steps either way.
  const bool last_only = problem.output.steps == StepOutput::last;
  if (held == 0)
    os << "no " << kind << " held: the result keeps ";
  else if (last_only && iterate)
    os << "the result keeps the scalars of the " << held << " " << kind << (held == 1 ? "" : "s")
       << " that held (output.steps \"last\")";
  else if (last_only && held > 1)
    os << "the result keeps the last of the " << held << " " << kind << "s that held (output.steps \"last\")";
  else
    os << "the result keeps the " << held << " " << kind << (held == 1 ? "" : "s") << " that held";
  if (iterate)
    os << (held == 0 ? "" : " and ") << "the last iterate (converged 0), which is not an answer";
  else if (steps.dropped_iterate())
    os << (held == 0 ? "nothing (" : ", not the last iterate (")
       << (steps.dropped_unfit() ? "it holds non-finite values)"
                                 : "set output.iterate to keep it, flagged as not converged)");
  return os.str();
}

}  // namespace

Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel) {
  try {
    parallel::ThreadTaskRunner runner(parallel::choose_threads(problem.solver.threads, problem.bodies.size()));
    return solve(problem, observer, cancel, runner);
  } catch (const std::exception& e) {  // no thread for the pool
    Result result;
    result.stop_reason = StopReason::error;
    result.message = std::string("internal error: ") + e.what();
    return result;
  }
}

Result solve(const Problem& problem, Observer& observer, const CancelToken& cancel, parallel::TaskRunner& runner) {
  const auto start = std::chrono::steady_clock::now();
  const auto seconds_since_start = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  Result result;
  result.method = to_string(problem.solver.method);
  result.enforcement = to_string(problem.solver.enforcement);
  result.warnings = problem.warnings;  // what the job reader's checks found (check/initial_gaps.hpp)
  const ddm::MethodFacts& facts = ddm::facts_of(problem.solver.method);
  try {
    if (runner.distributed() && !facts.not_distributed.empty()) {
      result.stop_reason = StopReason::error;
      result.message = facts.not_distributed;
      return result;
    }
    // Adaptivity refines the meshes: it works on its own copy of the problem.
    Problem working;
    const bool adaptive = problem.adaptivity.enabled;
    if (adaptive) working = problem;
    const Problem& active = adaptive ? working : problem;
    ddm::RunFrame frame(active.solver, observer, cancel, runner, start);
    ddm::ContactSystem system(active, runner, facts.factorization, frame.stop_check());
    result.setup_seconds = system.setup_seconds();
    result.factorization_seconds = system.factorization_seconds();
    if (system.cancelled()) {
      result.stop_reason = StopReason::cancelled;
      result.message = "cancelled during the set-up (assembly and factorisation of the bodies): nothing solved yet";
      result.wall_seconds = seconds_since_start();
      return result;
    }
    if (!system.ok()) {
      result.stop_reason = StopReason::error;
      result.message = system.error();
      result.wall_seconds = seconds_since_start();
      return result;
    }
    const std::unique_ptr<ddm::ContactMethod> method = ddm::make_method(system, active.solver.method);
    // Every step's scalars; the fields the job keeps, streamed to the observer's sink if it has one. Not for a
    // method whose solution is checked once the run ends (then every step is checked before any is kept).
    ddm::StepLog steps(problem.output, facts.checks_held_bodies ? nullptr : observer.step_sink());
    if (adaptive) {
      // Adaptivity refines at the loading's end (a load path, if any, is solved anew on each mesh).
      frame.state().load = fem::LoadPoint::end_of(problem.loading.factors.size() - 1, problem.loading.factors.back());
      adapt::run_adaptive(working, system, frame, *method, steps);
    } else {
      const ddm::HeldPath held = ddm::run_load_steps(system, problem.loading.factors, frame, *method, steps);
      ddm::MethodOutcome& loading = frame.outcome();
      if (problem.collapse.enabled && loading.converged) {
        limit::run_collapse(system, problem.collapse, frame, *method, steps, result.collapse);
      } else if (!loading.converged && !loading.refused && loading.stop_reason != StopReason::cancelled &&
                 !frame.stop_requested()) {
        // Why the step failed, by statics: a collapse (no equilibrium, its mechanism) or the solver.
        result.collapse = limit::judge_failed_step(system, frame.state().load,
                                                   problem.collapse.enabled ? "the dead loads" : "the loads",
                                                   frame.stop_check(), &held);
        if (problem.collapse.enabled) result.collapse.verdict = "dead_loads_fail";
        loading.message += "; " + result.collapse.words;
      }
    }
    static_cast<RunOutcome&>(result) = static_cast<RunOutcome&&>(frame.take_outcome());
    result.factorization_seconds = system.total_factorization_seconds();
    if (!result.converged) result.kept = what_the_result_keeps(active, steps);
    if (!result.kept.empty()) result.message += "; " + result.kept;
    result.streamed_steps = steps.streamed();
    result.steps = steps.take_steps();
    result.step_history = steps.take_summaries();
    if (facts.checks_held_bodies)
      refuse_unheld_bodies(active, result, steps.dropped_iterate() ? &steps.dropped_step() : nullptr);
    if (result.stop_reason != StopReason::error && result.stop_reason != StopReason::cancelled) refuse_tension(result);
    refuse_below_resolution(active, result);
    add_warnings(active, result);
    if (result.updates > 0 && !result.steps.empty()) {
      std::ostringstream os;
      os << "; remaining penetration " << max_penetration(result.steps.back());
      result.message += os.str();
    }
  } catch (const std::exception& e) {
    result.stop_reason = StopReason::error;
    result.message = std::string("internal error: ") + e.what();
  }
  result.wall_seconds = seconds_since_start();
  return result;
}

}  // namespace contact
