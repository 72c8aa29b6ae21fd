// The target run as accurate as a given answer (issue 50), for test_adaptive_defaults and bench_adaptivity. Header
// only, standard headers only.
#pragma once

#include <cmath>
#include <vector>

namespace contact::testing {

// A step of an adaptive run: its unknowns (2 x nodes), its true error and its pressure estimate.
struct TargetStop {
  long dofs;
  double error, estimate;
};

// The fewest unknowns of a target run whose last step's error is at most `error`, read off the steps of one run
// with a finer target (or one never met): a target T stops at the first step whose estimate is at most T, so the
// stops a target can make are the steps where the estimate reaches a new low; the first of those within `error`.
// 0 if none is.
inline long target_run_for(const std::vector<TargetStop>& steps, double error) {
  double low = HUGE_VAL;
  for (const TargetStop& s : steps) {
    if (!(s.estimate < low)) continue;
    low = s.estimate;
    if (s.error <= error) return s.dofs;
  }
  return 0;
}

}  // namespace contact::testing
