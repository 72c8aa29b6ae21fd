// Where a solve stands on the job's load path (docs/job-format.md, "loading"): the load step, the loading's factors
// at the ends of that step and the previous one, and the fraction t of the way between them (a load step that is cut
// into sub-steps, ddm/load_steps.cpp). A body's loads and prescribed values are its conditions at factor 1 scaled by
// this point (fem::BodySolver): the loading's factor for the conditions without a history, each history's own value
// for the others. The point is run state (ddm/run_state.hpp): the outer loops move it, the bodies only read it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace contact::fem {

struct LoadPoint {
  size_t step = 0;               // the load step (0-based)
  double previous_factor = 0.0;  // the loading's factor at the end of step - 1 (0 before the first step)
  double factor = 1.0;           // the loading's factor at the end of `step`
  double t = 1.0;                // the fraction of the way from the end of step - 1 to the end of `step`
  // A collapse analysis's load multiplier lambda: the factor of the live loads (0 while the loading brings the dead
  // loads on; limit/collapse.hpp raises it once the loading's last step holds).
  double multiplier = 0.0;

  // The end of step `step`, at the loading's factor `factor` there (the default point: the first step, whole).
  static LoadPoint end_of(size_t step, double factor) { return LoadPoint{step, 0.0, factor, 1.0}; }

  // The loading's factor here: every factor is interpolated linearly within a step.
  double value() const { return t == 1.0 ? factor : previous_factor + t * (factor - previous_factor); }

  // The factor here of a condition with its own history (one value per step, the last repeated; 0 before the first
  // step); without one, value().
  double of_history(const std::vector<double>& history) const {
    if (history.empty()) return value();
    const double end = history[std::min(step, history.size() - 1)];
    const double start = step == 0 ? 0.0 : history[std::min(step - 1, history.size() - 1)];
    return t == 1.0 ? end : start + t * (end - start);
  }
  // The factor here of a condition: a live load's is the multiplier, else of_history(history).
  double of_condition(const std::vector<double>& history, bool live) const {
    return live ? multiplier : of_history(history);
  }
};

}  // namespace contact::fem
