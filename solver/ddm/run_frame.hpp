// The frame of a run: what every level of a solve receives (the adapter, the load steps, the augmented Lagrangian,
// a contact method, an interface solver) instead of the settings, the observer, the runner and the stop request
// passed one by one. It owns
//   - the solver settings (read by every level from here, never passed beside the frame);
//   - the one stop check, stop_requested(): true means stop, as every stop callback of the layers below returns
//     (linalg's StepCallback, MPRGP's products, the BEM's and the factorisations' polls, which get stop_check());
//   - report(): the one way an iteration is reported (elapsed time stamped, the observer told, the history kept);
//   - the outcome being built at this level (outcome()), which nested() folds into the enclosing level's;
//   - the run state (state(): the load point, slip origins, augmented-Lagrangian multipliers; run_state.hpp), one per
//     run, shared by the nested frames: the outer loops write it, the methods read it beside the const system.
// A loop over inner solves (load steps, augmented-Lagrangian updates, adaptive steps) runs each in a nested frame:
// its reports reach the observer numbered on from the iterations so far and marked (the update they belong to,
// the refined counts), and its work adds up in the enclosing outcome (append).
#pragma once

#include "contact_system.hpp"

#include <chrono>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace contact::ddm {

// How a level ended, what it cost (RunOutcome, what the Result reports) and the answer it hands on.
struct MethodOutcome : RunOutcome {
  Displacements u;  // final displacements per body
  Pressures z;      // final contact pressures per pair, where they are not the penalty pressures of u (exact)
  Pressures q;      // friction: final tangential multipliers per pair (empty: frictionless; mortar/pair.hpp)
  std::vector<Eigen::VectorXd> rigid_amplitudes;  // per body: floating bodies' rigid-mode amplitudes (else empty)
  // Refused before any solve (statics: friction cannot hold the loads, ddm/friction_statics.hpp; or the settings):
  // a smaller increment of the same step would be refused too (load_steps.cpp cuts only the other failures).
  bool refused = false;
};

// What a nested solve's reports carry besides their iteration number: the augmented-Lagrangian update they
// belong to (if > 0) and, on the first report only, the per-body counts of elements refined before the solve.
struct InnerMarks {
  int update = 0;
  std::vector<int> refined;
  double multiplier = std::numeric_limits<double>::quiet_NaN();  // a collapse analysis's trial (NaN: none)
};

class RunFrame {
 public:
  using Clock = std::chrono::steady_clock;

  // The top frame of a run, its clock started at `start`.
  RunFrame(const SolverSettings& settings, Observer& observer, const CancelToken& cancel, parallel::TaskRunner& runner,
           Clock::time_point start = Clock::now());
  RunFrame(const RunFrame&) = delete;
  RunFrame& operator=(const RunFrame&) = delete;

  const SolverSettings& settings() const { return settings_; }
  parallel::TaskRunner& runner() const { return runner_; }
  // Where an iterative method starts (the previous step's or update's displacements), or null.
  const Displacements* warm_start() const { return warm_; }
  // The run's state (the top frame's; a nested frame shares it).
  RunState& state() { return *state_; }
  const RunState& state() const { return *state_; }

  // The one stop check: true when the run must stop (a cancel was asked). In a distributed run the token is the
  // one the processes agree on (set on every rank in the same collective operation), so every rank gets the same
  // answer at the same point.
  bool stop_requested() const { return cancel_.cancelled(); }
  // The same check for the layers below that know no frame (factorisations, BEM solves).
  std::function<bool()> stop_check() const {
    return [this] { return stop_requested(); };
  }
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  // Reports one iteration, numbered within this frame: stamps the elapsed time, tells the observer (numbered on
  // across the enclosing frames, with their marks) and keeps it in this frame's outcome history.
  void report(IterationReport r);
  // Reports an adaptive step to the observer.
  void report(const AdaptiveStepReport& r) const;
  // Reports a load step's end, a cut or a collapse trial to the observer (its elapsed time stamped).
  void report(LoadStepReport r) const;

  MethodOutcome& outcome() { return outcome_; }
  const MethodOutcome& outcome() const { return outcome_; }
  MethodOutcome take_outcome() { return std::move(outcome_); }

  // Runs `solve(RunFrame& inner)` in a frame nested in this one, starting from `warm` (null: no warm start), and
  // folds the inner outcome into this frame's (append); returns this frame's outcome, the total so far.
  template <class Solve>
  MethodOutcome& nested(const Displacements* warm, InnerMarks marks, Solve&& solve) {
    RunFrame inner(*this, marks, warm);
    solve(inner);
    append(inner.take_outcome(), marks);
    return outcome_;
  }

  // Folds an inner outcome in: its history renumbered from this frame's iterations and marked, its iterations and
  // work (updates, subdomain solves, interface iterations, the interface solver used) added, and its answer (u, z,
  // q, rigid amplitudes, gamma) and stop (reason, converged, refused, message) written over this frame's. The
  // loop then says what it adds itself (a prefix to the message, its own stop).
  void append(MethodOutcome inner, const InnerMarks& marks);

 private:
  RunFrame(RunFrame& parent, InnerMarks marks, const Displacements* warm);
  void notify(IterationReport r);  // to the observer, through the enclosing frames

  const SolverSettings& settings_;
  Observer& observer_;
  const CancelToken& cancel_;
  parallel::TaskRunner& runner_;
  Clock::time_point start_;
  const Displacements* warm_ = nullptr;
  RunState own_state_;  // the top frame's
  RunState* state_ = &own_state_;
  RunFrame* parent_ = nullptr;  // nested: the enclosing frame, its iterations when this one began, the marks
  int offset_ = 0;
  InnerMarks marks_;
  MethodOutcome outcome_;
};

}  // namespace contact::ddm
