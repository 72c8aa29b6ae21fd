// Benchmark of h-adaptivity on seed_layers (prints a table; never pass/fail):
//   build/bench/bench_adaptivity [--quick]
// Error of the contact pressure against a uniform overkill solution of the same penalty problem, versus the
// number of unknowns, for uniform refinement and for adaptive refinement of both bodies (converge, estimate,
// refine) with the FEM-BEM and the ZZ indicators; the DOFs uniform refinement needs for the same error
// (log-log interpolation) and the ratio; and the time spent in the indicators (for FEM-BEM: the BEM) against
// the solves.
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "bench_support.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace contact;
using nlohmann::json;
using contact::bench::now;

namespace {

Result run(const json& job) {
  const Problem problem = bench::parse_or_exit(job);
  Observer quiet;
  CancelToken cancel;
  return solve(problem, quiet, cancel);
}

// Reference pressure profile p(x) along the slave edge, piecewise linear between its nodes.
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
  Profile pr;
  for (Eigen::Index j = 0; j < f.pressure.size(); ++j) {
    pr.x.push_back(f.position(j, 0));
    pr.p.push_back(f.pressure[j]);
  }
  return pr;
}

// Relative L2 error of a pair's nodal pressure (piecewise linear) against the reference, on a fine sampling.
double pressure_error(const PairField& f, const Profile& ref) {
  const Profile mine = profile(f);
  double e2 = 0, r2 = 0;
  const int n = 8000;
  for (int i = 0; i <= n; ++i) {
    const double x = 4.0 * i / n, w = (i == 0 || i == n) ? 0.5 : 1.0;
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

json seed(int nx, int ny) {
  json job = json::parse(std::ifstream(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers.json"));
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = nx;
    b["mesh"]["block"]["ny"] = ny;
  }
  // The same discrete penalty problem on every mesh (theta = c * 1 / E), solved exactly on the interface.
  job["solver"] = {{"method", "interface_newton"}, {"enforcement", "penalty"}, {"penalty", {{"c", 0.05}, {"length", 1}}}};
  return job;
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const int overkill = quick ? 256 : 512;
  double t0 = now();
  const Result ref = run(seed(overkill, overkill / 4));
  const Profile reference = profile(ref.steps.back().pairs.at(0));
  std::printf("reference: uniform %dx%d per body, %ld unknowns, %.1f s; contact force %.6g\n", overkill, overkill / 4,
              total_dofs(ref, ref.iterations), now() - t0, ref.steps.back().pairs[0].force);

  // Uniform refinement.
  std::vector<std::pair<double, double>> uniform;  // (log dofs, log error)
  std::printf("\nuniform refinement\n  %9s %12s %12s\n", "dofs", "p error L2", "force");
  for (int nx = 8; nx <= (quick ? 64 : 128); nx *= 2) {
    const Result r = run(seed(nx, nx / 4));
    const double e = pressure_error(r.steps.back().pairs[0], reference);
    const long d = total_dofs(r, r.iterations);
    uniform.push_back({std::log(static_cast<double>(d)), std::log(e)});
    std::printf("  %9ld %12.4e %12.6g\n", d, e, r.steps.back().pairs[0].force);
  }
  auto uniform_dofs_for = [&](double error) {
    const double le = std::log(error);
    for (size_t i = 0; i + 1 < uniform.size(); ++i) {
      const auto [d0, e0] = uniform[i];
      const auto [d1, e1] = uniform[i + 1];
      if (le <= e0 && le >= e1) return std::exp(d0 + (d1 - d0) * (le - e0) / (e1 - e0));
    }
    // Beyond the table: extrapolate with the last slope.
    const auto [d0, e0] = uniform[uniform.size() - 2];
    const auto [d1, e1] = uniform.back();
    return std::exp(d1 + (d1 - d0) * (le - e1) / (e1 - e0));
  };

  for (const char* indicator : {"fem_bem", "zz"}) {
    json job = seed(8, 2);
    job["adaptivity"] = {{"indicator", indicator}, {"delta", 0.1}, {"strategy", "converge_then_refine"},
                         {"max_level", 8}, {"max_steps", quick ? 5 : 8}};
    t0 = now();
    const Result r = run(job);
    const double wall = now() - t0;
    std::printf("\nadaptive, %s indicator (both bodies, from 8x2), delta 0.1: wall %.2f s; indicators %.2f s summed over the bodies (run in parallel), %.0f %% of the wall time\n",
                indicator, wall, r.indicator_seconds, 100 * r.indicator_seconds / wall);
    std::printf("  %4s %9s %12s %14s %7s\n", "step", "dofs", "p error L2", "uniform dofs", "ratio");
    for (const auto& s : r.steps) {
      const double e = pressure_error(s.pairs.at(0), reference);
      const long d = total_dofs(r, s.iteration);
      const double u = uniform_dofs_for(e);
      std::printf("  %4d %9ld %12.4e %14.0f %7.1f\n", s.index, d, e, u, u / static_cast<double>(d));
    }
    std::printf("  stop: %s\n", r.message.c_str());
  }
  return 0;
}
