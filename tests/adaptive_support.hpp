// Helpers of the adaptive tests (test_adaptive.cpp, test_adaptive_target.cpp): the paper's test with the job's
// defaults, the contact pressure as a profile and issue 30's measure of its error, the unknowns of a step.
#pragma once

#include "contact/result.hpp"
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace contact::testing {

// The pressure along a pair's slave edge, piecewise linear between its nodes (x sorted; no pressure: 0).
struct PressureProfile {
  std::vector<double> x, p;
  explicit PressureProfile(const PairField& f) {
    std::vector<std::pair<double, double>> v;
    for (Eigen::Index j = 0; j < f.pressure.size(); ++j)
      v.emplace_back(f.position(j, 0), std::isfinite(f.pressure[j]) ? f.pressure[j] : 0.0);
    std::sort(v.begin(), v.end());
    for (const auto& [xj, pj] : v) {
      x.push_back(xj);
      p.push_back(pj);
    }
  }
  double at(double q) const {
    const auto it = std::upper_bound(x.begin(), x.end(), q);
    if (it == x.begin()) return p.front();
    if (it == x.end()) return p.back();
    const size_t i = static_cast<size_t>(it - x.begin()) - 1;
    return p[i] + (p[i + 1] - p[i]) * (q - x[i]) / (x[i + 1] - x[i]);
  }
};

// Relative L2 error of a pressure over lo <= x <= hi (by default 0 <= x <= 1.5, the paper's test) against a
// reference (trapezoidal rule on n intervals, finer than any mesh compared), the measure of issue 30.
inline double pressure_error(const PairField& f, const PressureProfile& reference, double lo = 0.0, double hi = 1.5,
                             int n = 15000) {
  const PressureProfile mine(f);
  double e2 = 0, r2 = 0;
  for (int i = 0; i <= n; ++i) {
    const double x = lo + (hi - lo) * i / n, w = (i == 0 || i == n) ? 0.5 : 1.0;
    e2 += w * std::pow(mine.at(x) - reference.at(x), 2);
    r2 += w * std::pow(reference.at(x), 2);
  }
  return std::sqrt(e2 / r2);
}

// seed_layers with the job's defaults (exact contact), both bodies nx x nx / 4.
inline nlohmann::json seed_layers_defaults(int nx) {
  nlohmann::json job = example("seed_layers.json");
  job.erase("solver");
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = nx;
    b["mesh"]["block"]["ny"] = nx / 4;
  }
  return job;
}

// The paper's test's overkill reference: an adaptive run that does not use the pressure estimate (the stress
// indicator's contact marking with delta 0.01 and 11 levels, 9 steps: ~195k unknowns, the contact edge at
// h = 1/4096), within ~0.01 % of the solution (test_adaptive_target.cpp says how that was measured).
inline nlohmann::json seed_layers_overkill() {
  nlohmann::json job = seed_layers_defaults(8);
  job["adaptivity"] = {{"delta", 0.01}, {"max_level", 11}, {"stop_tolerance", 0}, {"max_steps", 9}};
  return job;
}

// A step's unknowns counted as 2 x nodes (hanging and supported nodes included), from its meshes.
inline long mesh_unknowns(const Step& step) {
  long dofs = 0;
  for (const auto& b : step.bodies) dofs += 2L * b.mesh.num_nodes();
  return dofs;
}

// The job's start refined uniformly: every cell at every step (delta below any indicator, plain marking), `levels`
// levels, each kept (output.steps "all"): the reference of "fewer unknowns than uniform refinement".
inline Result uniform_levels(nlohmann::json job, int levels) {
  job["adaptivity"] = {{"indicator", "zz"},   {"delta", 1e-12},      {"marking", "plain"}, {"stop_tolerance", 0},
                       {"max_steps", levels}, {"max_level", levels}, {"max_dofs", 2000000}};
  job["output"] = {{"steps", "all"}};
  return run(job);
}

// The unknowns (after the constraints) of a step, from its last iteration report.
inline long unknowns(const Result& r, int iteration) {
  long dofs = 0;
  for (const auto& it : r.history)
    if (it.iteration == iteration) {
      dofs = 0;
      for (const auto& b : it.bodies) dofs += b.dofs;
    }
  return dofs;
}

}  // namespace contact::testing
