// Benchmark of floating bodies: api/examples/stack3_floating.json (the middle block held only by its contacts)
// against the same stack with the middle block restrained (api/examples/stack3.json's clamp at its far end), both
// with the default solver (interface Newton, exact), at growing meshes. Prints a table; never pass/fail:
//   build/bench/bench_floating [--scales 1,2,4,8,16] [--repeats 3]
// Each mesh is the example's scaled by the factor in both directions. Columns: wall time (the best of the
// repeats), active-set steps, the floating/restrained time ratio, and the two contact forces (equal for the
// floating block: its equilibrium).
#include "contact/solve.hpp"
#include "bench_support.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace contact;
using nlohmann::json;
using contact::bench::now;

namespace {

json example(const std::string& name, int scale) {
  json job = json::parse(std::ifstream(std::string(CONTACT_SOURCE_DIR) + "/api/examples/" + name));
  job.erase("solver");  // the default method and enforcement for both
  for (auto& b : job["bodies"]) {
    b["mesh"]["block"]["nx"] = b["mesh"]["block"]["nx"].get<int>() * scale;
    b["mesh"]["block"]["ny"] = b["mesh"]["block"]["ny"].get<int>() * scale;
  }
  return job;
}

struct Run {
  double seconds = 1e300;
  int steps = 0;
  double force_top = 0, force_bottom = 0;
  bool converged = false;
  long unknowns = 0;
};

Run best_of(const json& job, int repeats) {
  const Problem p = bench::parse_or_exit(job);
  Run best;
  for (const auto& b : p.bodies) best.unknowns += 2L * b.mesh.num_nodes();
  for (int r = 0; r < repeats; ++r) {
    Observer quiet;
    CancelToken cancel;
    const double t0 = now();
    const Result result = solve(p, quiet, cancel);
    const double seconds = now() - t0;
    best.converged = result.converged;
    if (!result.converged) {
      std::fprintf(stderr, "%s did not converge: %s\n", p.name.c_str(), result.message.c_str());
      return best;
    }
    best.seconds = std::min(best.seconds, seconds);
    best.steps = result.iterations;
    best.force_top = result.steps.back().pairs[0].force;
    best.force_bottom = result.steps.back().pairs[1].force;
  }
  return best;
}


}  // namespace

int main(int argc, char** argv) {
  std::vector<int> scales = {1, 2, 4, 8, 16};
  int repeats = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--scales") scales = bench::parse_int_list(argv[i + 1]);
    else if (flag == "--repeats") repeats = std::max(1, std::stoi(argv[i + 1]));
  }
  std::printf("stack3: three blocks, the middle one floating (held by its contacts) or clamped at its far end;\n"
              "default solver (interface Newton, exact); best of %d runs; %u hardware threads\n",
              repeats, std::thread::hardware_concurrency());
  std::printf("%-6s %9s  %-10s %8s %6s  %-10s %8s %6s  %7s  %13s %13s\n", "scale", "unknowns", "", "wall s", "steps",
              "", "wall s", "steps", "ratio", "force top", "force bottom");
  for (int scale : scales) {
    const Run held = best_of(example("stack3.json", scale), repeats);
    const Run floating = best_of(example("stack3_floating.json", scale), repeats);
    std::printf("%-6d %9ld  %-10s %8.3f %6d  %-10s %8.3f %6d  %7.2f  %13.6g %13.6g%s\n", scale, floating.unknowns,
                "restrained", held.seconds, held.steps, "floating", floating.seconds, floating.steps,
                floating.seconds / held.seconds, floating.force_top, floating.force_bottom,
                held.converged && floating.converged ? "" : "  (not converged)");
    std::fflush(stdout);
  }
  std::printf("\nratio: floating over restrained wall time. steps: active-set steps of the interface Newton method.\n");
  return 0;
}
