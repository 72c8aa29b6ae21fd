// Benchmark of the default solver (exact dual mortar contact by interface Newton) on the paper's problem at
// growing meshes, against one elastic solve of the same meshes, the paper's own scheme and the monolithic
// references (prints a table; never pass/fail):
//   build/bench/bench_contact [--sizes 128,256,512,1024] [--monolithic-up-to 512] [--exact-monolithic-up-to 256]
// seed_layers with nx x nx/4 elements per body. Every row runs in a child process, so that its peak memory
// (the child's maximum resident set) is its own. Columns: wall time, peak memory, iterations or active-set
// steps, the ratio of the wall time to "one factorisation + solve" (assemble and factorise both bodies, bodies in
// parallel, and one back-substitution each) measured in the same run, and the total contact force.
#include "ddm/contact_system.hpp"
#include "contact/solve.hpp"
#include "bench_support.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace contact;
using contact::bench::now;
using nlohmann::json;

namespace {

struct Figures {
  double seconds = -1, force = 0, setup = 0;
  int steps = 0;
  bool converged = false;
  double peak_mb = 0;
};

// Runs `work` in a child process; returns its figures and its peak resident memory.
Figures in_child(const std::function<Figures()>& work) {
  int fd[2];
  if (pipe(fd) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    const Figures f = work();
    char line[256];
    const int n = std::snprintf(line, sizeof line, "%.17g %.17g %.17g %d %d\n", f.seconds, f.force, f.setup, f.steps,
                                f.converged ? 1 : 0);
    if (write(fd[1], line, static_cast<size_t>(n)) != n) _exit(1);
    _exit(0);
  }
  close(fd[1]);
  std::string text;
  char buffer[256];
  ssize_t got;
  while ((got = read(fd[0], buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<size_t>(got));
  close(fd[0]);
  int status = 0;
  struct rusage usage;
  std::memset(&usage, 0, sizeof usage);
  wait4(pid, &status, 0, &usage);
  Figures f;
  int converged = 0;
  std::istringstream in(text);
  in >> f.seconds >> f.force >> f.setup >> f.steps >> converged;
  f.converged = converged != 0;
  f.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
  return f;
}

json seed_layers(int nx) {
  json job = json::parse(std::ifstream(std::string(CONTACT_SOURCE_DIR) + "/api/examples/seed_layers.json"));
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = nx;
    b["mesh"]["block"]["ny"] = nx / 4;
  }
  return job;
}

Figures one_solve(const json& job) {
  const Problem p = bench::parse_or_exit(job);
  const double t0 = now();
  parallel::ThreadTaskRunner runner(parallel::choose_threads(0, p.bodies.size()));
  ddm::ContactSystem system(p, runner, ddm::ContactSystem::Factorization::plain);
  const auto u = system.solve_bodies(ddm::Displacements(p.bodies.size()), fem::LoadPoint{});
  Figures f;
  f.seconds = now() - t0;
  f.setup = system.setup_seconds();
  f.converged = system.ok() && !u.empty();
  return f;
}

Figures solve_job(const json& job) {
  const Problem p = bench::parse_or_exit(job);
  Observer quiet;
  CancelToken cancel;
  const double t0 = now();
  const Result r = solve(p, quiet, cancel);
  Figures f;
  f.seconds = now() - t0;
  f.setup = r.setup_seconds;
  f.steps = r.iterations;
  f.converged = r.converged;
  if (!r.steps.empty())
    for (const auto& pair : r.steps.back().pairs) f.force += pair.force;
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes = {128, 256, 512, 1024};
  int monolithic_up_to = 512, exact_monolithic_up_to = 256;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--sizes")
      sizes = bench::parse_int_list(argv[i + 1]);
    else if (flag == "--monolithic-up-to")
      monolithic_up_to = std::stoi(argv[i + 1]);
    else if (flag == "--exact-monolithic-up-to")
      exact_monolithic_up_to = std::stoi(argv[i + 1]);
  }
  std::printf("seed_layers, nx x nx/4 Q1 elements per body, 2 bodies; %u hardware threads\n",
              std::thread::hardware_concurrency());
  std::printf("%-11s %9s  %-44s %8s %8s %6s %7s %12s\n", "mesh/body", "unknowns", "run", "wall s", "peak MB", "steps",
              "ratio", "force");
  for (int nx : sizes) {
    const json base = seed_layers(nx);
    const long unknowns = 2L * 2 * (nx + 1) * (nx / 4 + 1);
    char mesh[32];
    std::snprintf(mesh, sizeof mesh, "%dx%d", nx, nx / 4);
    const Figures one = in_child([&] { return one_solve(base); });
    auto row = [&](const char* name, const Figures& f) {
      std::printf("%-11s %9ld  %-44s %8.3f %8.0f %6d %7.2f %12.6g%s\n", mesh, unknowns, name, f.seconds, f.peak_mb,
                  f.steps, f.seconds / one.seconds, f.force, f.converged ? "" : "  (not converged)");
      std::fflush(stdout);
    };
    row("one factorisation + solve (reference time)", one);
    json defaults = base;
    defaults.erase("solver");
    row("default: interface Newton, exact", in_child([&] { return solve_job(defaults); }));
    row("paper's scheme (neumann, gamma 0.02, paper)", in_child([&] { return solve_job(base); }));
    json neumann = base;
    neumann["solver"] = {{"method", "neumann"}, {"enforcement", "augmented_lagrangian"}};
    row("neumann + Anderson + aug. Lagrangian (exact)", in_child([&] { return solve_job(neumann); }));
    if (nx <= monolithic_up_to) {
      json mono = base;
      mono["solver"] = {
          {"method", "monolithic"}, {"enforcement", "penalty"}, {"penalty", {{"c", 0.05}, {"length", 1}}}};
      row("monolithic penalty Newton (reference)", in_child([&] { return solve_job(mono); }));
    }
    if (nx <= exact_monolithic_up_to) {
      json mono = base;
      mono["solver"] = {{"method", "monolithic"}};
      row("monolithic exact, sparse LU (reference)", in_child([&] { return solve_job(mono); }));
    }
  }
  std::printf(
      "\nsteps: active-set steps (interface Newton, monolithic exact), iterations (neumann), Newton steps\n"
      "(monolithic penalty). The paper's scheme and the penalty reference solve the penalty problem (c = 0.05):\n"
      "their force is lower than the exact one.\n");
  return 0;
}
