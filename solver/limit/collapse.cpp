#include "collapse.hpp"

#include "mechanism.hpp"
#include "statics.hpp"

#include "../ddm/driver.hpp"

#include <cmath>
#include <limits>

namespace contact::limit {

namespace {

using ddm::Displacements;
using ddm::MethodOutcome;
using ddm::Pressures;

struct Loads {
  std::vector<Resultant> dead, live;
};

// The bodies' load resultants at `at`: the dead ones (multiplier 0) and the live ones at multiplier 1.
Loads loads_at(const ddm::ContactSystem& system, const RigidBlocks& blocks, fem::LoadPoint at) {
  Loads out;
  at.multiplier = 0.0;
  out.dead = load_resultants(system, blocks, at);
  at.multiplier = 1.0;
  out.live = load_resultants(system, blocks, at);
  for (size_t a = 0; a < out.live.size(); ++a) out.live[a] -= out.dead[a];
  return out;
}

// The answer of the last state that held, restored as the run's answer at the end.
struct Held {
  double multiplier = 0.0;
  Displacements u;
  Pressures z, q, slip_origin;
  std::vector<Eigen::VectorXd> rigid_amplitudes;
  static Held of(const MethodOutcome& o, const ddm::RunState& state, double multiplier) {
    return Held{multiplier, o.u, o.z, o.q, state.slip_origin, o.rigid_amplitudes};
  }
};

// The joints that are open or slip over most of their length in a held step: where the mechanism shows itself.
std::string joints_that_give(const Step& step) {
  std::string out;
  int listed = 0, more = 0;
  for (const auto& pair : step.pairs) {
    const JointResults j = joint_results(pair);
    std::string what;
    if (j.open_fraction >= 0.5) what = "open over " + shown(100 * j.open_fraction) + " %";
    if (j.slip_fraction >= 0.5)
      what += (what.empty() ? "" : ", ") + std::string("slipping over ") + shown(100 * j.slip_fraction) + " %";
    if (what.empty()) continue;
    if (listed == 6) {
      ++more;
      continue;
    }
    out += (listed++ ? "; " : "") + ("'" + pair.name + "' " + what);
  }
  if (more) out += "; and " + std::to_string(more) + " more";
  return out;
}

std::string statics_words(const CollapseResult& c) {
  if (std::isinf(c.statics_bound))
    return "the bodies as rigid blocks carry any multiple of the live loads (they press the joints shut)";
  if (std::isnan(c.statics_bound)) return "";
  return "the bodies as rigid blocks with associated friction carry at most lambda = " + shown(c.statics_bound) +
         " (an upper bound of lambda_c)";
}

void word_verdict(CollapseResult& c, const std::string& last_failure, const std::string& at_held) {
  std::string w;
  const std::string statics = statics_words(c);
  if (c.verdict == "collapse") {
    w = "collapse at lambda_c = " + shown(0.5 * (c.held + c.failed)) + ": lambda = " + shown(c.held) +
        " held and lambda = " + shown(c.failed) + " did not (" +
        (c.failed_by_statics ? std::string("above the statics bound: no solve can hold it")
                             : "the trial's solve: " + last_failure) +
        "), after " + std::to_string(c.solves) + " trial solve" + (c.solves == 1 ? "" : "s");
    if (!statics.empty()) w += "; " + statics;
    if (!std::isnan(c.statics_bound) && !std::isinf(c.statics_bound) && c.held < 0.98 * c.statics_bound)
      w += "; lambda_c is " + shown(100 * (1 - c.held / c.statics_bound)) +
           " % below that bound: non-associated friction collapses below it (sliding joints that cannot dilate), "
           "or the solver failed near the limit";
    if (!c.mechanism.words.empty()) w += "; mechanism (rigid blocks, at the bound): " + c.mechanism.words;
  } else if (c.verdict == "holds") {
    w = "no collapse up to max_multiplier = " + shown(c.held) + " (it held, after " + std::to_string(c.solves) +
        " trial solve" + (c.solves == 1 ? "" : "s") + ")";
    if (!statics.empty()) w += "; " + statics;
  } else {
    w = "the collapse analysis stopped before it bracketed lambda_c: lambda = " + shown(c.held) + " held" +
        (std::isnan(c.failed) ? std::string() : " and lambda = " + shown(c.failed) + " did not") + ", after " +
        std::to_string(c.solves) + " trial solves (" + last_failure + ")";
    if (!statics.empty()) w += "; " + statics;
  }
  if (!at_held.empty()) w += "; at the last state that held: " + at_held;
  c.words = std::move(w);
}

}  // namespace

void run_collapse(const ddm::ContactSystem& system, const CollapseSpec& spec, ddm::RunFrame& frame,
                  ddm::ContactMethod& method, ddm::StepLog& steps, CollapseResult& out) {
  out.analysed = true;
  out.tolerance = spec.tolerance;
  ddm::RunState& state = frame.state();
  MethodOutcome& total = frame.outcome();
  const double tol = spec.tolerance;

  // 1. The statics: the bound and its mechanism.
  const RigidBlocks blocks = rigid_blocks(system);
  const Loads loads = loads_at(system, blocks, state.load);
  const StaticsAnswer statics = largest_multiplier(blocks, loads.dead, loads.live);
  double hi = std::numeric_limits<double>::quiet_NaN();  // the smallest multiplier known not to hold
  if (statics.status == StaticsAnswer::Status::bounded) {
    out.statics_bound = statics.multiplier;
    out.mechanism = describe_mechanism(system, blocks, statics.velocity);
    hi = statics.multiplier * (1 + tol / 4);
    out.failed_by_statics = true;
  } else if (statics.status == StaticsAnswer::Status::unbounded) {
    out.statics_bound = std::numeric_limits<double>::infinity();
  }
  const bool bounded = std::isfinite(out.statics_bound);

  // 2-3. The trials, each from the last state that held.
  Held held = Held::of(total, state, 0.0);
  const int first_index = steps.held();
  bool solve_failed = false;
  std::string last_failure, stopped;
  double next = spec.first > 0 ? spec.first : bounded ? 0.5 * out.statics_bound : 1.0;
  while (true) {
    if (!std::isnan(hi) && hi - held.multiplier <= tol * held.multiplier) {
      out.verdict = "collapse";
      break;
    }
    if (bounded && out.statics_bound <= 0) {  // the live loads cannot be carried at all
      out.verdict = "collapse";
      hi = 0.0;
      break;
    }
    if (held.multiplier >= spec.max_multiplier) {
      out.verdict = "holds";
      break;
    }
    if (out.solves == spec.max_solves) {
      out.verdict = "solver_failed";
      stopped = "max_solves = " + std::to_string(spec.max_solves) + " reached";
      break;
    }
    double trial = std::min(next, spec.max_multiplier);
    if (!std::isnan(hi) && (trial >= hi || trial <= held.multiplier)) trial = 0.5 * (held.multiplier + hi);
    state.slip_origin = held.slip_origin;
    state.load.multiplier = trial;
    ddm::InnerMarks marks;
    marks.multiplier = trial;
    const double started = frame.elapsed();
    const int iterations_before = total.iterations;
    frame.nested(&held.u, marks, [&](ddm::RunFrame& inner) { ddm::run_enforced(system, inner, method); });
    out.trials.push_back({trial, total.converged, total.iterations - iterations_before, frame.elapsed() - started});
    LoadStepReport report;
    report.kind = LoadStepReport::Kind::trial;
    report.step = static_cast<int>(out.trials.size());
    report.multiplier = trial;
    report.held = total.converged;
    report.iterations = out.trials.back().iterations;
    report.load_factor = state.load.value();
    frame.report(report);
    ++out.solves;
    if (solve_failed) ++out.bracket_solves;
    if (total.stop_reason == StopReason::cancelled || frame.stop_requested()) {
      out.verdict = "solver_failed";
      stopped = "cancelled";
      break;
    }
    if (total.converged) {
      const double previous = held.multiplier;
      state.slip_origin = system.tangential_jumps(total.u);
      held = Held::of(total, state, trial);
      Step step = ddm::step_of(system, total, state);
      step.index = first_index + out.solves - 1;
      step.load_factor = state.load.value();
      step.multiplier = trial;
      steps.push_back(std::move(step));
      if (!std::isnan(hi))
        next = !solve_failed && bounded ? out.statics_bound * (1 - tol / 4) : 0.5 * (held.multiplier + hi);
      else
        next =
            statics.status == StaticsAnswer::Status::unbounded ? spec.max_multiplier : trial + 2 * (trial - previous);
    } else {
      hi = trial;
      solve_failed = true;
      out.failed_by_statics = false;
      last_failure = total.message;
      next = 0.5 * (held.multiplier + hi);
    }
  }
  out.held = held.multiplier;
  out.failed = hi;
  if (!std::isnan(hi) && !solve_failed) out.failed_by_statics = true;
  if (stopped == "cancelled")
    last_failure = "cancelled";
  else if (!stopped.empty())
    last_failure = stopped;

  // The answer: the last state that held.
  total.u = std::move(held.u);
  total.z = std::move(held.z);
  total.q = std::move(held.q);
  total.rigid_amplitudes = std::move(held.rigid_amplitudes);
  state.slip_origin = std::move(held.slip_origin);
  state.load.multiplier = out.held;
  word_verdict(out, last_failure, !steps.empty() ? joints_that_give(steps.back()) : std::string());
  total.refused = false;
  if (out.verdict == "solver_failed") {
    total.converged = false;
    total.stop_reason = stopped == "cancelled" ? StopReason::cancelled : StopReason::max_iterations;
  } else {
    total.converged = true;
    total.stop_reason = StopReason::converged;
  }
  total.message = out.words;
}

}  // namespace contact::limit
