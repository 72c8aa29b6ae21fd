// Benchmark of h-adaptivity on the paper's test (prints tables; never pass/fail), issues 20, 30 and 50:
//   build/bench/bench_adaptivity [--quick]
// seed_layers with the job's defaults (exact contact by interface Newton), both bodies adaptive from 8 x 2 cells.
// The error is the relative L2 norm of the contact pressure over 0 <= x <= 1.5 against two uniform solutions: the
// issue's 512 x 128 and a finer 1024 x 256 (256 x 64 and 512 x 128 with --quick). The issue's reference has an
// error of its own of ~0.2 % (the square-root edge on h = 1/128; docs/algorithm.md, "What the plateau was"), so
// errors below ~0.25 % are read against the finer one. Printed: uniform refinement 8 x 2 .. 512 x 128 (256 x 64 with
// --quick); every adaptive step of each run (FEM-BEM with the default marking, the paper's plain marking, ZZ, and
// smaller deltas, and the targets 0.5, 0.2 and 0.1 % of adaptivity.target_error) with its unknowns, the errors
// against both uniform references and against an overkill adaptive solution (~0.01 % from the solution), the
// step's pressure estimate and its effectivity (estimate / error against the overkill), the uniform unknowns for
// its error against the finer reference
// (log-log interpolation between the two measured uniform meshes around it; ">N" below the finest measured) and
// their ratio; then, per run, the measured ratio at 0.5 % (the issue's reference): the unknowns of the first
// uniform mesh at or below 0.5 % over those of the first adaptive step at or below 0.5 %, and the last step's
// ratio two ways (issue 50, item 2), unknowns counted as 2 x nodes as the issue counts them: against the issue's
// reference (uniform 512 x 128; its own error is 0.23 % against the overkill, so an answer closer to the solution
// than that reads as ~0.25 % however good it is) and against the overkill (the uniform curve measured against it
// too). Then the defaults against a target run of the same accuracy (issue 50, item 1): the target run that meets
// the default's last error with the fewest unknowns, read off one long target run (a run with target T stops at
// the first step whose estimate is at most T: the steps where the estimate reaches a new low are the stops a
// target can make). Then Cattaneo-Mindlin (cattaneo_mindlin_runs) and, without --quick, two cylinders
// (two_cylinder_runs), each with the same comparison.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "bench_support.hpp"
#include "../tests/cattaneo_mindlin.hpp"
#include "../tests/target_runs.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace contact;
using contact::bench::now;
using nlohmann::json;

namespace {

constexpr double kTarget = 0.005;  // the issue's 0.5 %
constexpr double kRange = 1.5;     // the error is measured over 0 <= x <= 1.5

// Keeps each adaptive step's pressure estimate (adapt/pressure_estimate.hpp).
class Estimates final : public Observer {
 public:
  void on_adaptive_step(const AdaptiveStepReport& r) override { pressure.push_back(r.pressure_estimate); }
  std::vector<double> pressure;
};

Result run(const json& job, Observer* observer = nullptr) {
  const Problem problem = bench::parse_or_exit(job);
  Observer quiet;
  CancelToken cancel;
  return solve(problem, observer ? *observer : quiet, cancel);
}

// A pressure profile p(x) along the slave edge, piecewise linear between its nodes.
struct Profile {
  std::vector<double> x, p;
  double at(double q) const {
    if (q <= x.front()) return p.front();
    for (size_t i = 0; i + 1 < x.size(); ++i)
      if (q <= x[i + 1]) return p[i] + (p[i + 1] - p[i]) * (q - x[i]) / (x[i + 1] - x[i]);
    return p.back();
  }
};

Profile profile(const PairField& f) {
  std::vector<std::pair<double, double>> v;
  for (Eigen::Index j = 0; j < f.pressure.size(); ++j) v.emplace_back(f.position(j, 0), f.pressure[j]);
  std::sort(v.begin(), v.end());
  Profile pr;
  for (const auto& [x, p] : v) {
    pr.x.push_back(x);
    pr.p.push_back(std::isfinite(p) ? p : 0.0);
  }
  return pr;
}

// Relative L2 error over [lo, hi] (the paper's test: [0, kRange]) of a pair's nodal pressure (piecewise linear)
// against the reference, by the trapezoidal rule on 15,000 intervals (finer than any mesh here).
double pressure_error(const PairField& f, const Profile& ref, double lo = 0.0, double hi = kRange) {
  const Profile mine = profile(f);
  double e2 = 0, r2 = 0;
  const int n = 15000;
  for (int i = 0; i <= n; ++i) {
    const double x = lo + (hi - lo) * i / n, w = (i == 0 || i == n) ? 0.5 : 1.0;
    const double d = mine.at(x) - ref.at(x);
    e2 += w * d * d;
    r2 += w * ref.at(x) * ref.at(x);
  }
  return std::sqrt(e2 / r2);
}

long total_dofs(const Result& r, int iteration) {
  for (const auto& it : r.history)
    if (it.iteration == iteration) {
      long d = 0;
      for (const auto& b : it.bodies) d += b.dofs;
      return d;
    }
  return 0;
}

// seed_layers at nx x ny cells per body with the job's defaults (no solver section: exact contact).
json seed(int nx, int ny) {
  json job = json::parse(std::ifstream(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers.json"));
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = nx;
    b["mesh"]["block"]["ny"] = ny;
  }
  job.erase("solver");
  return job;
}

struct Point {
  long dofs;
  double error;
};

// 2 x nodes over the bodies of step k (the unknowns as issue 50 counts them: hanging and held nodes included).
long nodes2(const Step& s) {
  long n = 0;
  for (const auto& b : s.bodies) n += 2L * b.mesh.num_nodes();
  return n;
}

using contact::testing::target_run_for;
using Stop = contact::testing::TargetStop;

// Uniform unknowns for an error, interpolated log-log between the measured meshes around it; NaN outside them.
double uniform_dofs_for(const std::vector<Point>& uniform, double error) {
  for (size_t i = 0; i + 1 < uniform.size(); ++i) {
    const double e0 = std::log(uniform[i].error), e1 = std::log(uniform[i + 1].error), le = std::log(error);
    if (le <= e0 && le >= e1) {
      const double d0 = std::log(static_cast<double>(uniform[i].dofs)),
                   d1 = std::log(static_cast<double>(uniform[i + 1].dofs));
      return std::exp(d0 + (d1 - d0) * (le - e0) / (e1 - e0));
    }
  }
  return std::nan("");
}

long first_at_target(const std::vector<Point>& points) {
  for (const Point& p : points)
    if (p.error <= kTarget) return p.dofs;
  return 0;
}

// The references and the uniform curve against each (the issue's first); `overkill`: an adaptive run that does
// not use the pressure estimate (delta 0.01, 11 levels, 9 steps), ~0.01 % from the solution, against which the
// estimate's effectivity is read.
struct References {
  Profile issue, fine, overkill;
  std::vector<Point> uniform_issue, uniform_fine;
  std::vector<Point> issue_nodes, overkill_nodes;  // 2 x nodes against the issue's reference and the overkill
};

// The uniform unknowns for an error on a curve, and the ratio to `dofs` as text ("-" outside the curve; ">" below
// its finest mesh, whose unknowns are then the bound).
std::string uniform_ratio(const std::vector<Point>& uniform, double error, long dofs) {
  double u = uniform_dofs_for(uniform, error);
  const bool below = std::isnan(u) && error < uniform.back().error;
  if (below) u = static_cast<double>(uniform.back().dofs);
  char text[64];
  if (std::isnan(u))
    std::snprintf(text, sizeof text, "-");
  else
    std::snprintf(text, sizeof text, "%s%.0f uniform: %s%.1fx", below ? ">" : "", u, below ? ">" : "",
                  u / static_cast<double>(dofs));
  return text;
}

std::vector<Stop> adaptive_run(const char* label, const json& adaptivity, const References& refs) {
  json job = seed(8, 2);
  job["adaptivity"] = adaptivity;
  job["output"] = {{"steps", "all"}};  // every step's fields (adaptive jobs keep only the last by default)
  Estimates estimates;
  const double t0 = now();
  const Result r = run(job, &estimates);
  const double wall = now() - t0;
  std::printf("\nadaptive, %s: %s\n  wall %.2f s (%.2f s a step), indicators %.2f s (summed over the bodies)\n", label,
              adaptivity.dump().c_str(), wall, wall / static_cast<double>(r.steps.size()), r.indicator_seconds);
  std::printf("  %4s %9s %9s %12s %12s %12s %12s %6s %14s %7s\n", "step", "unknowns", "2 x nodes", "p err issue",
              "p err fine", "p err over", "estimate", "effect", "uniform equiv.", "ratio");
  std::vector<Point> points;
  std::vector<Stop> stops;
  for (size_t k = 0; k < r.steps.size(); ++k) {
    const Step& s = r.steps[k];
    const long dofs = total_dofs(r, s.iteration);
    const Point p{dofs, pressure_error(s.pairs.at(0), refs.issue)};
    const double fine = pressure_error(s.pairs.at(0), refs.fine);
    const double over = pressure_error(s.pairs.at(0), refs.overkill);
    const double estimate = k < estimates.pressure.size() ? estimates.pressure[k] : std::nan("");
    points.push_back(p);
    stops.push_back({nodes2(s), over, estimate});
    double u = uniform_dofs_for(refs.uniform_fine, fine);
    const bool below = std::isnan(u) && fine < refs.uniform_fine.back().error;
    if (below) u = static_cast<double>(refs.uniform_fine.back().dofs);
    std::printf("  %4d %9ld %9ld %12.4e %12.4e %12.4e %12.4e %6.2f", s.index, dofs, nodes2(s), p.error, fine, over,
                estimate, estimate / over);
    if (std::isnan(u))
      std::printf(" %14s %7s\n", "-", "-");
    else
      std::printf(" %s%13.0f %s%6.1f\n", below ? ">" : " ", u, below ? ">" : " ", u / static_cast<double>(dofs));
  }
  std::printf("  stop: %s\n", r.message.c_str());
  const long adaptive_dofs = first_at_target(points), uniform_dofs = first_at_target(refs.uniform_issue);
  if (adaptive_dofs > 0 && uniform_dofs > 0)
    std::printf(
        "  at %.1f %% (issue's reference): adaptive %ld unknowns, uniform %ld (first measured mesh at or "
        "below): ratio %.1f\n",
        100 * kTarget, adaptive_dofs, uniform_dofs, static_cast<double>(uniform_dofs) / adaptive_dofs);
  else
    std::printf("  at %.1f %%: not reached (%s)\n", 100 * kTarget, adaptive_dofs > 0 ? "uniform" : "adaptive");
  const Step& last = r.steps.back();
  std::printf(
      "  last step, %ld = 2 x nodes: against uniform 512 x 128 %.3f %% (%s); against the overkill %.3f %% "
      "(%s)\n",
      nodes2(last), 100 * points.back().error,
      uniform_ratio(refs.issue_nodes, points.back().error, nodes2(last)).c_str(), 100 * stops.back().error,
      uniform_ratio(refs.overkill_nodes, stops.back().error, nodes2(last)).c_str());
  return stops;
}

// The defaults' last step against the target run of the same accuracy (target_run_for), as issue 50 asks.
void against_target(const char* example, const std::vector<Stop>& defaults, const std::vector<Stop>& target_steps) {
  const Stop& d = defaults.back();
  const long t = target_run_for(target_steps, d.error);
  if (t > 0)
    std::printf(
        "\n%s: the defaults stop at %ld unknowns (2 x nodes) with the pressure %.3f %% wrong; the target run "
        "that meets %.3f %% stops at %ld: ratio %.2f\n",
        example, d.dofs, 100 * d.error, 100 * d.error, t, static_cast<double>(d.dofs) / t);
  else
    std::printf(
        "\n%s: the defaults stop at %ld unknowns with the pressure %.3f %% wrong; no target stop of the long "
        "run meets it\n",
        example, d.dofs, 100 * d.error);
}

// Half the contact zone's length along the slave edge at step k (the extent's square-root extrapolation,
// contact_extent.hpp): on the R* = 7.1 cylinders the arc is the chord to 0.03 %.
double half_width(const Result& r, size_t k) {
  const StepSummary& s = r.step_history.at(k);
  return 0.5 * (s.contact_end.at(0) - s.contact_begin.at(0));
}

// api/examples/two_cylinders_gmsh.json (its Gmsh file read from there: bench::parse_or_exit), the given
// adaptivity, every step kept.
json two_cylinders(const json& adaptivity) {
  json job = json::parse(std::ifstream(std::string(CONTACT_SOURCE_DIR) + "/api/examples/two_cylinders_gmsh.json"));
  job["adaptivity"] = adaptivity;
  job["output"] = {{"steps", "all"}};
  return job;
}

// Two cylinders (R 10 on R 25, plane strain, Gmsh, non-matching): every step's pressure error against an
// overkill solution (the goal-oriented marking of a target of 0.02 %, 12 levels: ~1M unknowns, itself within about
// 0.01 % of the solution: docs/algorithm.md, "Refinement for the pressure's target"), the estimate and its
// effectivity, the peak pressure and the half-width against Hertz at the computed force; and the graded start
// refined uniformly, level by level.
void two_cylinder_runs() {
  const double R = 1.0 / (1.0 / 10 + 1.0 / 25), inv_E = (1 - 0.3 * 0.3) / 2.1e5 + (1 - 0.33 * 0.33) / 7.0e4;
  double t0 = now();
  const Result over = run(two_cylinders({{"target_error", 0.0002}, {"max_steps", 30}, {"max_dofs", 4000000}}));
  const PairField& o = over.steps.back().pairs.at(0);
  const double a_over = std::sqrt(4 * o.force * R * inv_E / M_PI);
  const Profile reference = profile(o);
  std::printf("\ntwo cylinders: reference target 0.02 %%, %zu steps, %ld unknowns, %.1f s; force %.6g, a %.5f\n",
              over.steps.size(), total_dofs(over, over.iterations), now() - t0, o.force, a_over);
  t0 = now();
  const Result levels = run(two_cylinders({{"indicator", "zz"},
                                           {"delta", 1e-12},
                                           {"marking", "plain"},
                                           {"stop_tolerance", 0},
                                           {"max_steps", 4},
                                           {"max_level", 4},
                                           {"max_dofs", 2000000}}));
  std::printf("\ntwo cylinders, the graded start refined uniformly (%.1f s):\n  %5s %9s %10s\n", now() - t0, "level",
              "unknowns", "p err");
  for (size_t k = 0; k < levels.steps.size(); ++k)
    std::printf("  %5zu %9ld %9.4f%%\n", k, total_dofs(levels, levels.steps[k].iteration),
                100 * pressure_error(levels.steps[k].pairs.at(0), reference, -1.5 * a_over, 1.5 * a_over));
  std::vector<Stop> defaults, finest;
  const std::vector<std::pair<const char*, json>> runs = {
      {"defaults", json::object()},
      {"contact marking (the defaults before issue 50)", {{"marking", "contact"}}},
      {"target_error 0.5 %", {{"target_error", 0.005}}},
      {"target_error 0.2 %", {{"target_error", 0.002}}},
      {"target_error 0.1 %", {{"target_error", 0.001}}}};
  for (const auto& [label, adaptivity] : runs) {
    Estimates estimates;
    t0 = now();
    const Result r = run(two_cylinders(adaptivity), &estimates);
    const double wall = now() - t0;
    std::printf("\ntwo cylinders, %s: wall %.1f s (%.1f s a step)\n", label, wall,
                wall / static_cast<double>(r.steps.size()));
    std::printf("  %4s %9s %10s %10s %6s %10s %10s %10s\n", "step", "unknowns", "p err", "estimate", "effect", "force",
                "peak-Hertz", "a-Hertz");
    std::vector<Stop> stops;
    for (size_t k = 0; k < r.steps.size(); ++k) {
      const PairField& p = r.steps[k].pairs.at(0);
      const double error = pressure_error(p, reference, -1.5 * a_over, 1.5 * a_over);
      const double estimate = k < estimates.pressure.size() ? estimates.pressure[k] : std::nan("");
      const double a = std::sqrt(4 * p.force * R * inv_E / M_PI), p0 = 2 * p.force / (M_PI * a);
      std::printf("  %4zu %9ld %9.4f%% %9.4f%% %6.2f %10.6g %9.3f%% %9.3f%%\n", k, total_dofs(r, r.steps[k].iteration),
                  100 * error, 100 * estimate, estimate / error, p.force, 100 * (p.pressure.maxCoeff() - p0) / p0,
                  100 * (half_width(r, k) - a) / a);
      stops.push_back({nodes2(r.steps[k]), error, estimate});
    }
    std::printf("  stop: %s\n", r.message.c_str());
    if (adaptivity.empty()) defaults = stops;
    finest = stops;
  }
  against_target("two cylinders (the pressure against the overkill)", defaults, finest);
}

// Cattaneo-Mindlin (tests/cattaneo_mindlin.hpp: R 60, mu 0.3, Q / (mu P) = 0.5) adaptive from 20 x 4 uniform cells
// per body, with the defaults, gradings 0.5 and 0.25, the contact marking (with and without grading 0.5) and with
// targets of 0.5, 0.2 and 0.1 %: every step's pressure error
// against Hertz at its own force, the pressure estimate and its effectivity, c / a against sqrt(1 - Q / (mu P))
// and the tangential traction's
// error against Mindlin's (in L2, and at the nodes only: tests/cattaneo_mindlin.hpp); then meshes graded towards
// the contact: 800 x 24, which misses the traction's 5 % in L2, and 1000 x 30, the smallest found to meet both.
void cattaneo_mindlin_runs() {
  const double Q = 0.5 * 0.3 * 2194.0;
  auto meets = [](const testing::MindlinFit& f) {
    return std::abs(f.c_over_a - f.theory) <= 0.03 && f.traction_error < 0.05;
  };
  std::vector<Stop> defaults, finest;
  for (const auto& [label, adaptivity] : std::vector<std::pair<const char*, json>>{
           {"defaults", json::object()},
           {"grading 0.5", {{"grading", 0.5}}},
           {"grading 0.25", {{"grading", 0.25}}},
           {"contact marking (the defaults before issue 50)", {{"marking", "contact"}}},
           {"contact marking, grading 0.5", {{"marking", "contact"}, {"grading", 0.5}}},
           {"target_error 0.5 %", {{"target_error", 0.005}}},
           {"target_error 0.2 %", {{"target_error", 0.002}}},
           {"target_error 0.1 %", {{"target_error", 0.001}}}}) {
    json job = testing::cattaneo_mesh(20, 4, false, Q);
    job["adaptivity"] = adaptivity;
    job["output"] = {{"steps", "all"}};
    Estimates estimates;
    const double t0 = now();
    const Result r = run(job, &estimates);
    const double wall = now() - t0;
    std::printf("\nCattaneo-Mindlin, %s: wall %.1f s (%.2f s a step)\n", label, wall,
                wall / static_cast<double>(r.steps.size()));
    std::printf("  %4s %9s %10s %10s %6s %8s %8s %9s %9s %s\n", "step", "unknowns", "p err", "estimate", "effect",
                "c/a", "theory", "t err", "at nodes", "");
    std::vector<Stop> stops;
    for (size_t k = 0; k < r.steps.size(); ++k) {
      const PairField& p = r.steps[k].pairs.at(0);
      const testing::MindlinFit fit = testing::mindlin_fit(p, Q);
      const double error = testing::hertz_pressure_error(p);
      const double estimate = k < estimates.pressure.size() ? estimates.pressure[k] : std::nan("");
      std::printf("  %4zu %9ld %9.3f%% %9.3f%% %6.2f %8.4f %8.4f %8.2f%% %8.2f%% %s\n", k,
                  total_dofs(r, r.steps[k].iteration), 100 * error, 100 * estimate, estimate / error, fit.c_over_a,
                  fit.theory, 100 * fit.traction_error, 100 * fit.nodal_traction_error, meets(fit) ? "meets" : "");
      stops.push_back({nodes2(r.steps[k]), error, estimate});
    }
    std::printf("  stop: %s\n", r.message.c_str());
    if (adaptivity.empty()) defaults = stops;
    finest = stops;  // (the last run: the finest target)
  }
  against_target("Cattaneo-Mindlin (the pressure against Hertz)", defaults, finest);
  std::printf("\nCattaneo-Mindlin, meshes graded towards the contact (grading 60)\n");
  for (const auto& [nx, ny] : {std::pair{800, 24}, std::pair{1000, 30}}) {
    const double t0 = now();
    const Result r = run(testing::cattaneo_mesh(nx, ny, true, Q));
    const testing::MindlinFit fit = testing::mindlin_fit(r.steps.back().pairs.at(0), Q);
    std::printf(
        "  %4d x %-3d %9ld unknowns, %.1f s: p err %.3f%%, c/a %.4f (theory %.4f), t err %.2f%% (at nodes "
        "%.2f%%) %s\n",
        nx, ny, total_dofs(r, r.iterations), now() - t0,
        100 * testing::hertz_pressure_error(r.steps.back().pairs.at(0)), fit.c_over_a, fit.theory,
        100 * fit.traction_error, 100 * fit.nodal_traction_error, meets(fit) ? "meets" : "");
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const int issue = quick ? 256 : 512, finer = 2 * issue;
  References refs;
  for (const int nx : {issue, finer}) {
    const double t0 = now();
    const Result ref = run(seed(nx, nx / 4));
    (nx == issue ? refs.issue : refs.fine) = profile(ref.steps.back().pairs.at(0));
    std::printf("reference: uniform %dx%d per body, %ld unknowns, %.1f s; contact force %.6g\n", nx, nx / 4,
                total_dofs(ref, ref.iterations), now() - t0, ref.steps.back().pairs[0].force);
  }

  {
    json overkill = seed(8, 2);
    overkill["adaptivity"] = {{"delta", 0.01}, {"max_level", 11}, {"stop_tolerance", 0}, {"max_steps", 9}};
    const double t0 = now();
    const Result ref = run(overkill);
    refs.overkill = profile(ref.steps.back().pairs.at(0));
    std::printf("reference: overkill adaptive %s, %ld unknowns, %.1f s\n", overkill["adaptivity"].dump().c_str(),
                total_dofs(ref, ref.iterations), now() - t0);
  }

  std::printf("\nuniform refinement\n  %9s %9s %9s %12s %12s %12s %12s\n", "cells", "unknowns", "2 x nodes",
              "p err issue", "p err fine", "p err over", "force");
  for (int nx = 8; nx <= issue; nx *= 2) {
    const Result r = run(seed(nx, nx / 4));
    const PairField& pair = r.steps.back().pairs[0];
    const long dofs = total_dofs(r, r.iterations), n2 = nodes2(r.steps.back());
    const double over = pressure_error(pair, refs.overkill);
    if (nx < issue) refs.uniform_issue.push_back({dofs, pressure_error(pair, refs.issue)});
    if (nx < issue) refs.issue_nodes.push_back({n2, refs.uniform_issue.back().error});
    refs.uniform_fine.push_back({dofs, pressure_error(pair, refs.fine)});
    refs.overkill_nodes.push_back({n2, over});
    char own[32] = "(itself)";
    if (nx < issue) std::snprintf(own, sizeof own, "%.4e", refs.uniform_issue.back().error);
    std::printf("  %4dx%-4d %9ld %9ld %12s %12.4e %12.4e %12.6g\n", nx, nx / 4, dofs, n2, own,
                refs.uniform_fine.back().error, over, pair.force);
  }
  {  // the finer reference on the overkill's curve too
    const long n2 = 2L * 2 * (finer + 1) * (finer / 4 + 1);
    Profile copy = refs.fine;
    double e2 = 0, r2 = 0;
    for (int i = 0; i <= 15000; ++i) {
      const double x = kRange * i / 15000, w = (i == 0 || i == 15000) ? 0.5 : 1.0;
      e2 += w * std::pow(copy.at(x) - refs.overkill.at(x), 2);
      r2 += w * std::pow(refs.overkill.at(x), 2);
    }
    refs.overkill_nodes.push_back({n2, std::sqrt(e2 / r2)});
    std::printf("  %4dx%-4d %9s %9ld %12s %12s %12.4e\n", finer, finer / 4, "", n2, "", "(itself)",
                refs.overkill_nodes.back().error);
  }

  // Issue 50: the defaults (the goal-oriented marking, stopped where the answer settled) and the indicator's
  // markings they replaced.
  const std::vector<Stop> defaults = adaptive_run("the defaults", json::object(), refs);
  const json base = {{"indicator", "fem_bem"}, {"delta", 0.1}};
  adaptive_run("FEM-BEM, contact marking (the defaults before issue 50)", base, refs);
  json plain = base;
  plain["marking"] = "plain";
  adaptive_run("FEM-BEM, the paper's plain marking", plain, refs);
  json zz = base;
  zz["indicator"] = "zz";
  adaptive_run("ZZ, contact marking", zz, refs);
  for (const double delta : {0.05, 0.03}) {
    json small = base;
    small["delta"] = delta;
    adaptive_run(delta == 0.05 ? "FEM-BEM, contact marking, delta 0.05" : "FEM-BEM, contact marking, delta 0.03", small,
                 refs);
  }
  // Issue 30, item 2: the job names the accuracy; the run stops at the first step whose estimate meets it.
  std::vector<Stop> finest;
  for (const double target : {0.005, 0.002, 0.001}) {
    char label[64];
    std::snprintf(label, sizeof label, "FEM-BEM, target_error %.1f %%", 100 * target);
    finest = adaptive_run(label, {{"target_error", target}}, refs);
  }
  against_target("the paper's test", defaults, finest);
  cattaneo_mindlin_runs();
  if (!quick) two_cylinder_runs();  // (minutes: the reference alone reaches ~1M unknowns)
  return 0;
}
