// contact-solve: the solver without the server.
//   contact-solve JOB.json [-o RESULT.hdf]     solve, print one progress line per iteration, write the result
//   contact-solve JOB.json --validate          only check the job
// Exit codes: 0 converged; 1 solver or I/O error; 2 invalid job (errors printed with their JSON pointers);
// 3 stopped without converging (max_iterations or cancelled; the result file is still written).
#include "io/result_file.hpp"
#include "job/job.hpp"
#include "solve.hpp"

#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>

namespace {

contact::CancelToken* g_cancel = nullptr;
extern "C" void on_interrupt(int) {
  if (g_cancel) g_cancel->cancel();  // an atomic store: async-signal-safe
}

const char* method_name(contact::Method m) {
  switch (m) {
    case contact::Method::interface_newton: return "interface_newton";
    case contact::Method::neumann: return "neumann";
    case contact::Method::robin: return "robin";
    case contact::Method::monolithic: return "monolithic";
  }
  return "?";
}

const char* enforcement_name(contact::Enforcement e) {
  switch (e) {
    case contact::Enforcement::exact: return "exact";
    case contact::Enforcement::penalty: return "penalty";
    case contact::Enforcement::augmented_lagrangian: return "augmented_lagrangian";
  }
  return "?";
}

// One line per iteration with what decides convergence: for the active-set methods (interface Newton, and the
// exact monolithic reference) the active set, its changes and the complementarity residual; for the
// fixed-point schemes both stopping measures; then per pair force, max pressure and active nodes.
class ProgressPrinter final : public contact::Observer {
 public:
  explicit ProgressPrinter(bool quiet) : quiet_(quiet) {}
  void on_iteration(const contact::IterationReport& r) override {
    if (quiet_) return;
    const bool active_set = r.measure == contact::Measure::complementarity;
    std::printf("%s %4d", active_set ? "step" : "iter", r.iteration);
    if (r.update > 0) std::printf("  update %3d", r.update);
    if (active_set)
      std::printf("  active %4d (changed %3d)  complementarity %.3e", r.active_nodes, r.active_set_changes,
                  r.complementarity);
    else if (r.measure == contact::Measure::gradient)
      std::printf("  gradient %.3e  active %4d (changed %3d)", r.fixed_point_residual, r.active_nodes, r.active_set_changes);
    else
      std::printf("  paper %.3e  residual %.3e", r.paper_criterion, r.fixed_point_residual);
    if (r.gamma > 0) std::printf("  gamma %.3g", r.gamma);
    for (const auto& p : r.pairs)
      std::printf("  | %s: force %.6g  p_max %.6g  active %d (%+d)", p.name.c_str(), p.force, p.max_pressure,
                  p.active_nodes, p.changed_nodes);
    std::printf("  %.2fs", r.elapsed_seconds);
    if (!r.note.empty()) std::printf("  [%s]", r.note.c_str());
    std::printf("\n");
    std::fflush(stdout);
  }

 private:
  bool quiet_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "contact-solve: frictionless contact of elastic bodies by domain decomposition (each body solved on its own).\n"
      "Methods (job field solver.method): interface_newton (default: exact dual-mortar contact, primal-dual active\n"
      "set on the bodies' interface Schur complements), neumann (the paper's penalty Neumann DDM (16)-(17)), robin,\n"
      "monolithic (reference). See docs/job-format.md."};
  app.set_version_flag("--version", std::string("contact-solve ") + contact::solver_version());
  std::string job_path, output;
  bool validate_only = false, quiet = false;
  long max_dofs = contact::job::Limits{}.max_dofs;
  int threads = -1;
  app.add_option("job", job_path, "contact job (JSON, see docs/job-format.md)")->required();
  app.add_option("-o,--output", output, "result file (HDF5; default: the job file's name with .hdf)");
  app.add_flag("--validate", validate_only, "only validate the job and exit");
  app.add_flag("-q,--quiet", quiet, "no per-iteration lines");
  app.add_option("--max-dofs", max_dofs, "reject jobs with more unknowns than this")->check(CLI::PositiveNumber);
  app.add_option("--threads", threads, "threads for the per-body solves (overrides the job; 0 = automatic)")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  contact::job::Limits limits;
  limits.max_dofs = max_dofs;
  // Gmsh mesh files are read relative to the job file's directory.
  auto parsed = contact::job::parse_file(job_path, limits);
  if (!parsed.ok()) {
    std::cerr << job_path << ": the job is invalid (" << parsed.errors.size() << " error"
              << (parsed.errors.size() == 1 ? "" : "s") << "):\n"
              << contact::job::format_errors(parsed.errors);
    return 2;
  }
  contact::Problem& problem = *parsed.problem;
  if (threads >= 0) problem.solver.threads = threads;
  if (validate_only) {
    long dofs = 0;
    for (const auto& b : problem.bodies) dofs += 2L * b.mesh.num_nodes();
    std::cout << job_path << ": valid (" << problem.bodies.size() << " bodies, " << problem.contacts.size()
              << " contact pairs, " << dofs << " dofs before constraints)\n";
    return 0;
  }
  if (output.empty()) output = std::filesystem::path(job_path).stem().string() + ".hdf";

  contact::CancelToken cancel;
  g_cancel = &cancel;
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);

  const bool fixed_point = problem.solver.method == contact::Method::neumann || problem.solver.method == contact::Method::robin;
  const bool adaptive_paper = problem.adaptivity.enabled && problem.adaptivity.strategy == contact::AdaptStrategy::paper;
  const bool active_set = !fixed_point && !adaptive_paper &&
                          (problem.solver.method == contact::Method::interface_newton ||
                           problem.solver.enforcement == contact::Enforcement::exact);
  std::printf("%s: %zu bodies, %zu contact pairs, method %s, enforcement %s\n", problem.name.c_str(),
              problem.bodies.size(), problem.contacts.size(), method_name(problem.solver.method),
              enforcement_name(problem.solver.enforcement));
  ProgressPrinter printer(quiet);
  const contact::Result result = contact::solve(problem, printer, cancel);
  g_cancel = nullptr;

  std::printf("stop: %s after %d %s, %.3f s (setup %.3f s): %s\n", contact::to_string(result.stop_reason),
              result.iterations, active_set ? "steps" : "iterations", result.wall_seconds, result.setup_seconds,
              result.message.c_str());
  if (result.steps.empty()) {
    std::cerr << "error: " << result.message << "\n";
    return 1;
  }
  for (const auto& p : result.steps.back().pairs) {
    double p_max = 0, penetration = 0;
    for (Eigen::Index j = 0; j < p.pressure.size(); ++j) {
      p_max = std::max(p_max, p.pressure[j]);
      penetration = std::max(penetration, p.penetration[j]);
    }
    if (p.enforcement == "exact")
      std::printf("pair %s: exact contact, force %.8g, max pressure %.8g, max penetration %.4g\n", p.name.c_str(),
                  p.force, p_max, penetration);
    else
      std::printf("pair %s: %s, theta %.4g, force %.8g, max pressure %.8g, max penetration %.4g\n", p.name.c_str(),
                  p.enforcement.c_str(), p.theta, p.force, p_max, penetration);
  }
  try {
    contact::io::write_result(output, problem, result);
    std::filesystem::path xmf = std::filesystem::path(output).replace_extension(".xmf");
    contact::io::write_xdmf(xmf.string(), std::filesystem::path(output).filename().string(), result);
    // ParaView's Xdmf3 readers abort on a bare file name (they join it with the data file's name): "./x.xmf".
    if (!xmf.has_parent_path()) xmf = std::filesystem::path(".") / xmf;
    std::printf("wrote %s and %s (in ParaView, open %s with the Xdmf3 Reader)\n", output.c_str(), xmf.string().c_str(),
                xmf.string().c_str());
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  if (result.stop_reason == contact::StopReason::error) return 1;
  return result.converged ? 0 : 3;
}
