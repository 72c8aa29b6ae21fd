// Benchmark of the DDM methods (prints a table; never pass/fail):
//   build/bench/bench_methods [--quick]
// seed_layers at three mesh sizes and stack3, every method driven to a fixed-point residual of 1e-8
// (interface Newton and monolithic: to their exact active set). Columns: subdomain solves per body
// (back-substitutions with the body's factorisation: the DDM's unit of work), iterations, wall time, the ratio
// of wall time to one elastic solve of the whole problem (assemble + factorise every body + one solve), and
// the contact force (all methods solve the same discrete problem, so it must agree).
#include "ddm/contact_system.hpp"
#include "contact/job.hpp"
#include "contact/solve.hpp"
#include "bench_support.hpp"

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace contact;
using contact::bench::now;
using nlohmann::json;

namespace {

Problem make(json job, const json& solver) {
  for (auto& [key, value] : solver.items()) job["solver"][key] = value;
  return bench::parse_or_exit(job);
}

double one_solve_seconds(const Problem& p) {
  const double t0 = now();
  parallel::ThreadTaskRunner runner(parallel::choose_threads(0, p.bodies.size()));
  ddm::ContactSystem system(p, runner);
  const auto u = system.solve_bodies(ddm::Displacements(p.bodies.size()), fem::LoadPoint{});
  (void)u;
  return now() - t0;
}

struct Row {
  std::string name;
  json solver;
};

void run_table(const std::string& title, const json& job, bool sweep) {
  const json tight = {{"criterion", "residual"},
                      {"tolerance", 1e-8},
                      {"max_iterations", 20000},
                      {"acceleration", "none"},
                      {"enforcement", "penalty"}};
  Problem base = make(job, tight);
  long dofs = 0;
  for (const auto& b : base.bodies) dofs += 2L * b.mesh.num_nodes();
  const double one = one_solve_seconds(base);
  std::printf(
      "\n%s: %ld dofs, %zu bodies; one elastic solve (assemble + factorise + solve, bodies in parallel) %.4f s\n",
      title.c_str(), dofs, base.bodies.size(), one);
  std::printf("  %-34s %8s %6s %9s %7s %14s  %s\n", "method", "solves", "iter", "wall s", "ratio", "force", "stop");

  std::vector<Row> rows = {{"paper scheme, gamma 0.02", {{"method", "neumann"}, {"gamma", 0.02}}}};
  if (sweep) {
    // Best fixed gamma: a short sweep below the stability bound (docs/algorithm.md, "Stability: which gamma
    // converges": gamma < 2 / (1 + mu_max / theta), about 0.067 on seed_layers).
    for (double g : {0.03, 0.045, 0.06}) {
      char name[64];
      std::snprintf(name, sizeof name, "paper scheme, gamma %.3g", g);
      rows.push_back({name, {{"method", "neumann"}, {"gamma", g}}});
    }
  }
  rows.push_back({"neumann, gamma auto", {{"method", "neumann"}, {"gamma", "auto"}}});
  rows.push_back(
      {"neumann, gamma auto + Anderson(10)", {{"method", "neumann"}, {"gamma", "auto"}, {"acceleration", "anderson"}}});
  rows.push_back({"robin psi=active_set, auto", {{"method", "robin"}, {"gamma", "auto"}}});
  rows.push_back(
      {"robin psi=active_set + Anderson", {{"method", "robin"}, {"gamma", "auto"}, {"acceleration", "anderson"}}});
  rows.push_back({"interface Newton", {{"method", "interface_newton"}}});
  rows.push_back({"monolithic Newton", {{"method", "monolithic"}}});
  rows.push_back({"interface Newton + aug. Lagrangian",
                  {{"method", "interface_newton"}, {"enforcement", "augmented_lagrangian"}}});
  for (const auto& row : rows) {
    json s = tight;
    for (auto& [k, v] : row.solver.items()) s[k] = v;
    const Problem p = make(job, s);
    Observer quiet;
    CancelToken cancel;
    const double t0 = now();
    const Result r = solve(p, quiet, cancel);
    const double wall = now() - t0;
    double force = 0;
    if (!r.steps.empty())
      for (const auto& pr : r.steps.back().pairs) force += pr.force;
    std::printf("  %-34s %8d %6d %9.3f %7.1f %14.8g  %s\n", row.name.c_str(), r.subdomain_solves, r.iterations, wall,
                wall / one, force, to_string(r.stop_reason));
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const bool quick = argc > 1 && std::string(argv[1]) == "--quick";
  const std::string dir = std::string(CONTACT_SOURCE_DIR) + "/api/examples/";
  json seed = json::parse(std::ifstream(dir + "seed_layers.json"));
  std::vector<std::pair<int, int>> sizes = {{32, 8}, {128, 32}, {448, 112}};
  if (quick) sizes = {{32, 8}};
  for (const auto& [nx, ny] : sizes) {
    json job = seed;
    for (auto& b : job["bodies"]) {
      b["mesh"]["block"]["nx"] = nx;
      b["mesh"]["block"]["ny"] = ny;
    }
    run_table("seed_layers " + std::to_string(nx) + "x" + std::to_string(ny) + " per body", job, true);
  }
  run_table("stack3", json::parse(std::ifstream(dir + "stack3.json")), false);
  std::printf(
      "\n(force: sum over the pairs; 'solves' for monolithic is 0: it factorises the coupled system instead)\n");
  return 0;
}
