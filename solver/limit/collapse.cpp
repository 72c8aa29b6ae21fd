#include "collapse.hpp"

#include "elastic_mechanism.hpp"
#include "mechanism.hpp"
#include "statics.hpp"

#include "../ddm/driver.hpp"

#include <algorithm>
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

// Each pair's centre of pressure at `step` (CollapseResult::Thrust): its arc length along the slave edge
// (JointResults::centre_of_pressure) placed on the edge's polyline.
std::vector<CollapseResult::Thrust> thrust_of(const Step& step) {
  std::vector<CollapseResult::Thrust> out;
  for (const auto& pair : step.pairs) {
    CollapseResult::Thrust t;
    t.pair = pair.name;
    t.slave_body = pair.slave_body;
    t.master_body = pair.master_body;
    const Eigen::Index n = pair.position.rows();
    if (n == 0 || pair.arc_length.size() != n) continue;
    t.first = pair.position.row(0).transpose();
    t.last = pair.position.row(n - 1).transpose();
    t.force = pair.force;
    t.eccentricity = pair.joint.eccentricity;
    const double s = pair.joint.centre_of_pressure;
    if (std::isfinite(s) && pair.force > 0) {
      Eigen::Index k = 1;
      while (k < n - 1 && pair.arc_length[k] < s) ++k;
      const double a = pair.arc_length[std::max<Eigen::Index>(k - 1, 0)], b = pair.arc_length[k];
      const double w = n > 1 && b > a ? std::clamp((s - a) / (b - a), 0.0, 1.0) : 0.0;
      t.point = ((1 - w) * pair.position.row(std::max<Eigen::Index>(k - 1, 0)) + w * pair.position.row(k)).transpose();
    }
    out.push_back(std::move(t));
  }
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
    if (c.mechanism.source == "elastic") {
      w += "; mechanism (the elastic solution's, into the last held state): " + c.mechanism.words;
      if (!c.statics_mechanism.words.empty() && c.statics_mechanism.kind != c.mechanism.kind)
        w += "; the rigid blocks' at the bound (associated friction) is " + c.statics_mechanism.words;
    } else if (!c.mechanism.words.empty()) {
      w += "; mechanism (rigid blocks, at the bound): " + c.mechanism.words;
    }
  } else if (c.verdict == "holds") {
    w = "no collapse up to max_multiplier = " + shown(c.held) + " (it held, after " + std::to_string(c.solves) +
        " trial solve" + (c.solves == 1 ? "" : "s") + ")";
    if (!statics.empty()) w += "; " + statics;
  } else if (c.failed_by_budget) {
    w = "the collapse analysis could not decide above lambda = " + shown(c.held) +
        " (it held): lambda = " + shown(c.failed) + " ran out of the iterative interface solver's budget (" +
        last_failure +
        "), which is the solver's limit, not a proof that nothing holds, so lambda_c >= " + shown(c.held) +
        " and a larger interface.max_iterations may bracket it; after " + std::to_string(c.solves) + " trial solves";
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

// One collapse analysis in its phases: the statics' bound, the trials (each one increment from the last held state),
// the answer restored to the last held state.
class CollapseRun {
 public:
  CollapseRun(const ddm::ContactSystem& system, const CollapseSpec& spec, ddm::RunFrame& frame,
              ddm::ContactMethod& method, ddm::StepLog& steps, CollapseResult& out)
      : system_(system), spec_(spec), frame_(frame), method_(method), steps_(steps), out_(out) {}

  void run() {
    out_.analysed = true;
    out_.tolerance = spec_.tolerance;
    bound_by_statics();
    live_loads();
    out_.start_displacement = live_displacement(frame_.outcome().u);
    held_ = Held::of(frame_.outcome(), frame_.state(), 0.0);
    first_index_ = steps_.held();
    double next = spec_.first > 0 ? spec_.first : bounded() ? 0.5 * out_.statics_bound : 1.0;
    while (!decided()) next = trial(next);
    finish();
  }

 private:
  bool bounded() const { return std::isfinite(out_.statics_bound); }

  // 1. The statics: the bound (its top, lambda_s (1 + tol/4), the bracket's top before any solve) and its mechanism.
  void bound_by_statics() {
    const RigidBlocks blocks = rigid_blocks(system_);
    const Loads loads = loads_at(system_, blocks, frame_.state().load);
    statics_ = largest_multiplier(blocks, loads.dead, loads.live, frame_.stop_check());
    if (statics_.status == StaticsAnswer::Status::bounded) {
      out_.statics_bound = statics_.multiplier;
      out_.statics_mechanism = describe_mechanism(system_, blocks, statics_.velocity);
      out_.statics_mechanism.source = "statics";
      hi_ = statics_.multiplier * (1 + spec_.tolerance / 4);
    } else if (statics_.status == StaticsAnswer::Status::unbounded) {
      out_.statics_bound = std::numeric_limits<double>::infinity();
    }
  }

  // The live loads at multiplier 1, per body (its owner's), and the sum of their nodal magnitudes over all bodies:
  // what the capacity curve's displacement is measured with (CollapseResult::Trial::displacement).
  void live_loads() {
    fem::LoadPoint at = frame_.state().load;
    live_.assign(system_.n_bodies(), Eigen::VectorXd());
    double magnitude = 0.0;
    for (size_t a = 0; a < system_.n_bodies(); ++a) {
      if (!system_.runner().owns(a)) continue;
      at.multiplier = 1.0;
      live_[a] = system_.body(a).external_load(at);
      at.multiplier = 0.0;
      live_[a] -= system_.body(a).external_load(at);
      for (Eigen::Index i = 0; i + 1 < live_[a].size(); i += 2) magnitude += live_[a].segment<2>(i).norm();
    }
    system_.runner().sum(&magnitude, 1);
    live_magnitude_ = magnitude;
  }

  // The live loads' displacement at the answer u (collective: every process calls it).
  double live_displacement(const Displacements& u) const {
    double work = 0.0;
    for (size_t a = 0; a < live_.size(); ++a)
      if (live_[a].size() > 0 && a < u.size() && u[a].size() == live_[a].size()) work += live_[a].dot(u[a]);
    system_.runner().sum(&work, 1);
    return live_magnitude_ > 0 ? work / live_magnitude_ : std::numeric_limits<double>::quiet_NaN();
  }

  // Whether the analysis has its verdict (bracketed, holds, out of solves).
  bool decided() {
    if (!std::isnan(hi_) && hi_ - held_.multiplier <= spec_.tolerance * held_.multiplier) {
      out_.verdict = "collapse";
    } else if (bounded() && out_.statics_bound <= 0) {  // the live loads cannot be carried at all
      out_.verdict = "collapse";
      hi_ = 0.0;
    } else if (held_.multiplier >= spec_.max_multiplier) {
      out_.verdict = "holds";
    } else if (out_.solves == spec_.max_solves) {
      out_.verdict = "solver_failed";
      stopped_ = "max_solves = " + std::to_string(spec_.max_solves) + " reached";
    }
    return !out_.verdict.empty();
  }

  // 2-3. One trial at `next` (moved into the bracket), from the last held state; returns the next trial's multiplier.
  double trial(double next) {
    ddm::RunState& state = frame_.state();
    MethodOutcome& total = frame_.outcome();
    double lambda = std::min(next, spec_.max_multiplier);
    if (!std::isnan(hi_) && (lambda >= hi_ || lambda <= held_.multiplier)) lambda = 0.5 * (held_.multiplier + hi_);
    state.slip_origin = held_.slip_origin;
    state.load.multiplier = lambda;
    ddm::InnerMarks marks;
    marks.multiplier = lambda;
    const double started = frame_.elapsed();
    const int iterations_before = total.iterations;
    const long interface_before = total.interface_iterations;
    frame_.nested(&held_.u, marks, [&](ddm::RunFrame& inner) { ddm::run_enforced(system_, inner, method_); });
    out_.trials.push_back({lambda, total.converged, total.iterations - iterations_before, frame_.elapsed() - started,
                           total.converged ? live_displacement(total.u) : std::numeric_limits<double>::quiet_NaN()});
    report(lambda);
    ++out_.solves;
    if (solve_failed_) ++out_.bracket_solves;
    if (total.stop_reason == StopReason::cancelled || frame_.stop_requested()) {
      out_.verdict = "solver_failed";
      stopped_ = "cancelled";
      return lambda;
    }
    if (!total.converged) {
      hi_ = lambda;
      solve_failed_ = true;
      last_failure_ = total.message;
      // Out of the iterative interface solver's budget: the solver's limit, not a proof that nothing holds (near
      // the limit its Coulomb iteration crawls; above it, it has no fixed point to reach).
      top_by_budget_ = total.interface_iterations - interface_before >= frame_.settings().interface.max_iterations;
      return 0.5 * (held_.multiplier + hi_);
    }
    const double previous = held_.multiplier;
    keep_held(lambda);
    if (!std::isnan(hi_))  // just under the statics' top while no solve failed, else the bracket's middle
      return !solve_failed_ && bounded() ? out_.statics_bound * (1 - spec_.tolerance / 4)
                                         : 0.5 * (held_.multiplier + hi_);
    // No bound: any multiple is carried by statics (try the largest asked), or growing increments.
    return statics_.status == StaticsAnswer::Status::unbounded ? spec_.max_multiplier
                                                               : lambda + 2 * (lambda - previous);
  }

  void report(double lambda) const {
    LoadStepReport r;
    r.kind = LoadStepReport::Kind::trial;
    r.step = static_cast<int>(out_.trials.size());
    r.multiplier = lambda;
    r.held = out_.trials.back().held;
    r.iterations = out_.trials.back().iterations;
    r.load_factor = frame_.state().load.value();
    frame_.report(r);
  }

  // A trial that held: the next trials start from it, and it is a result step with its multiplier.
  void keep_held(double lambda) {
    ddm::RunState& state = frame_.state();
    const MethodOutcome& total = frame_.outcome();
    state.slip_origin = system_.tangential_jumps(total.u);
    before_ = std::move(held_.u);
    held_ = Held::of(total, state, lambda);
    Step step = ddm::step_of(system_, total, state);
    step.index = first_index_ + out_.solves - 1;
    step.load_factor = state.load.value();
    step.multiplier = lambda;
    steps_.push_back(std::move(step));
  }

  // The collapse's mechanism: the elastic states' own (the increment into the last held state) when it passes its
  // check and the collapse was bracketed by a solve that failed, else the statics'.
  void mechanism() {
    out_.mechanism = out_.statics_mechanism;
    if (out_.verdict != "collapse" || out_.solves == 0 || before_.empty() || steps_.empty()) return;
    const RigidBlocks blocks = rigid_blocks(system_);
    const Loads loads = loads_at(system_, blocks, frame_.state().load);
    ElasticMechanism elastic = elastic_mechanism(system_, blocks, before_, held_.u, steps_.back(), loads.live);
    if (elastic.admissible) {
      out_.mechanism = std::move(elastic.mechanism);
    } else if (!out_.mechanism.words.empty()) {
      out_.mechanism.check = "the elastic states' mechanism was not taken: " + elastic.check;
    }
  }

  // The answer: the last state that held, and the verdict in words.
  void finish() {
    ddm::RunState& state = frame_.state();
    MethodOutcome& total = frame_.outcome();
    out_.held = held_.multiplier;
    out_.failed = hi_;
    out_.failed_by_statics = !std::isnan(hi_) && !solve_failed_;
    out_.failed_by_budget = solve_failed_ && top_by_budget_;
    if (out_.verdict == "collapse" && out_.failed_by_budget) out_.verdict = "solver_failed";
    if (!stopped_.empty()) last_failure_ = stopped_;
    mechanism();
    total.u = std::move(held_.u);
    total.z = std::move(held_.z);
    total.q = std::move(held_.q);
    total.rigid_amplitudes = std::move(held_.rigid_amplitudes);
    state.slip_origin = std::move(held_.slip_origin);
    state.load.multiplier = out_.held;
    word_verdict(out_, last_failure_, !steps_.empty() ? joints_that_give(steps_.back()) : std::string());
    if (!steps_.empty()) out_.thrust = thrust_of(steps_.back());
    total.refused = false;
    const bool answered = out_.verdict != "solver_failed";
    total.converged = answered;
    total.stop_reason = answered                  ? StopReason::converged
                        : stopped_ == "cancelled" ? StopReason::cancelled
                                                  : StopReason::max_iterations;
    total.message = out_.words;
  }

  const ddm::ContactSystem& system_;
  const CollapseSpec& spec_;
  ddm::RunFrame& frame_;
  ddm::ContactMethod& method_;
  ddm::StepLog& steps_;
  CollapseResult& out_;
  StaticsAnswer statics_;
  std::vector<Eigen::VectorXd> live_;  // the live loads at multiplier 1 of the bodies this process owns
  double live_magnitude_ = 0.0;        // sum of their nodal magnitudes over every body
  Held held_;
  Displacements before_;  // the state that held before held_ (the increment into held_ shows the mechanism)
  int first_index_ = 0;
  double hi_ = std::numeric_limits<double>::quiet_NaN();  // the smallest multiplier known not to hold
  bool solve_failed_ = false;
  bool top_by_budget_ = false;  // the bracket's top is a trial that ran out of interface.max_iterations
  std::string last_failure_, stopped_;
};

}  // namespace

void run_collapse(const ddm::ContactSystem& system, const CollapseSpec& spec, ddm::RunFrame& frame,
                  ddm::ContactMethod& method, ddm::StepLog& steps, CollapseResult& out) {
  CollapseRun(system, spec, frame, method, steps, out).run();
}

}  // namespace contact::limit
