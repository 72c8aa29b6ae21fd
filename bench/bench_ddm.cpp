// Benchmark of the solver core on seed_layers at growing mesh sizes (prints a table; never pass/fail).
//   build/bench/bench_ddm [path/to/seed_layers.json] [--quick]
// For each size: unknowns, the time of one elastic solve of the whole problem (assembly + factorisation of
// every body + one back-substitution, bodies in parallel), the DDM with the paper's parameters and stopping
// test, the DDM driven to a fixed-point residual of 1e-8 (gamma 0.05), and the monolithic Newton reference;
// and each one's total time divided by the one-solve time.
#include "ddm/contact_system.hpp"
#include "job/job.hpp"
#include "solve.hpp"
#include "bench_support.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

using namespace contact;
using nlohmann::json;
using contact::bench::now;

namespace {

Problem make(const json& base, int nx, int ny, const json& solver_overrides) {
  json job = base;
  for (auto& body : job["bodies"]) {
    body["mesh"]["block"]["nx"] = nx;
    body["mesh"]["block"]["ny"] = ny;
  }
  for (auto& [key, value] : solver_overrides.items()) job["solver"][key] = value;
  return bench::parse_or_exit(job);
}

struct Run {
  int iterations = 0;
  double seconds = 0, residual = 0, force = 0;
  bool converged = false;
};

Run run(const Problem& p) {
  Observer quiet;
  CancelToken cancel;
  const double t0 = now();
  const Result r = solve(p, quiet, cancel);
  Run out;
  out.seconds = now() - t0;
  out.iterations = r.iterations;
  out.converged = r.converged;
  out.residual = r.history.empty() ? 0 : r.history.back().fixed_point_residual;
  out.force = r.steps.empty() || r.steps.back().pairs.empty() ? 0 : r.steps.back().pairs[0].force;
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path = std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers.json";
  bool quick = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else
      path = a;
  }
  std::ifstream in(path);
  const json base = json::parse(in);
  std::vector<std::pair<int, int>> sizes = {{32, 8}, {128, 32}, {448, 112}};
  if (quick) sizes = {{32, 8}, {64, 16}};

  std::printf("seed_layers: two bodies solved in parallel (%u hardware threads)\n", std::thread::hardware_concurrency());
  std::printf("%9s %9s | %10s | %-28s | %-32s | %-28s\n", "mesh", "dofs", "1 solve s", "DDM paper criterion",
              "DDM to residual 1e-8 (gamma .05)", "monolithic Newton");
  std::printf("%9s %9s | %10s | %5s %8s %7s %6s | %5s %8s %9s %6s | %5s %8s %6s\n", "", "", "", "iter", "total s",
              "s/iter", "ratio", "iter", "total s", "s/iter", "ratio", "steps", "total s", "ratio");
  for (const auto& [nx, ny] : sizes) {
    const Problem paper = make(base, nx, ny, json::object());
    long dofs = 0;
    for (const auto& b : paper.bodies) dofs += 2L * b.mesh.num_nodes();

    // One elastic solve of the whole problem: assemble + factorise all bodies, one back-substitution each.
    double one_solve = 0;
    {
      const double t0 = now();
      ddm::ThreadTaskRunner runner(ddm::choose_threads(0, paper.bodies.size()));
      ddm::ContactSystem system(paper, runner);
      const auto u = system.solve_bodies(ddm::Displacements(paper.bodies.size()), runner);
      one_solve = now() - t0;
      (void)u;
    }
    const Run p = run(paper);
    const Run tight = run(make(base, nx, ny, {{"criterion", "residual"}, {"tolerance", 1e-8}, {"gamma", 0.05}, {"max_iterations", 5000}}));
    const Run mono = run(make(base, nx, ny, {{"method", "monolithic"}}));
    char mesh[32];
    std::snprintf(mesh, sizeof mesh, "%dx%d", nx, ny);
    std::printf("%9s %9ld | %10.4f | %5d %8.3f %7.4f %6.1f | %5d %8.3f %9.5f %6.1f | %5d %8.3f %6.1f\n", mesh, dofs,
                one_solve, p.iterations, p.seconds, p.seconds / std::max(1, p.iterations), p.seconds / one_solve,
                tight.iterations, tight.seconds, tight.seconds / std::max(1, tight.iterations), tight.seconds / one_solve,
                mono.iterations, mono.seconds, mono.seconds / one_solve);
    std::printf("%9s %9s   contact force: paper-criterion DDM %.6g (residual left %.3g), tight DDM %.6g, monolithic %.6g\n",
                "", "", p.force, p.residual, tight.force, mono.force);
    std::fflush(stdout);
  }
  return 0;
}
