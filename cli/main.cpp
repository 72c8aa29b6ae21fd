// contact-solve: the solver without the server.
//   contact-solve JOB.json [-o RESULT.hdf]     solve, print one progress line per iteration, write the result
//   contact-solve JOB.json --validate          only check the job
//   mpirun -n N contact-solve JOB.json ...     the bodies spread over N MPI ranks (docs/parallel.md)
// Exit codes: 0 converged; 1 solver or I/O error; 2 invalid job (errors printed with their JSON pointers);
// 3 stopped without converging (max_iterations or cancelled; the result file is still written).
#include "contact/progress_json.hpp"
#include "contact/result_file.hpp"
#include "contact/job.hpp"
#include "contact/session.hpp"
#include "contact/solve.hpp"

#include <CLI/CLI.hpp>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <unistd.h>

namespace {

// A stop request (SIGINT, SIGTERM, or SIGUSR1 which mpirun forwards to every rank): the solver sees it at its
// next iteration, on every rank at the same point (contact/session.hpp).
// One process: the request is the cancel token itself.
std::atomic<bool> g_stop_request{false};
std::atomic<contact::CancelToken*> g_direct_cancel{nullptr};
extern "C" void on_interrupt(int) {  // atomic loads and stores only: async-signal-safe
  g_stop_request.store(true);
  if (contact::CancelToken* token = g_direct_cancel.load()) token->cancel();
}

// From the first instruction of main: a stop that comes while the job is read, parsed or set up (SIGUSR1 would
// otherwise end the process at once, with no result) is kept and stops the solve at its first iteration.
void catch_stop_signals() {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
  std::signal(SIGUSR1, on_interrupt);
}

const char* method_name(contact::Method m) {
  switch (m) {
    case contact::Method::interface_newton:
      return "interface_newton";
    case contact::Method::neumann:
      return "neumann";
    case contact::Method::robin:
      return "robin";
    case contact::Method::monolithic:
      return "monolithic";
  }
  return "?";
}

const char* enforcement_name(contact::Enforcement e) {
  switch (e) {
    case contact::Enforcement::exact:
      return "exact";
    case contact::Enforcement::penalty:
      return "penalty";
    case contact::Enforcement::augmented_lagrangian:
      return "augmented_lagrangian";
  }
  return "?";
}

// One line per iteration with what decides convergence: for the active-set methods (interface Newton, and the
// exact monolithic reference) the active set, its changes and the complementarity residual; for the
// fixed-point schemes both stopping measures; then per pair force, max pressure and active nodes.
class ProgressPrinter final : public contact::Observer {
 public:
  ProgressPrinter(bool quiet, bool ndjson, contact::io::ProgressSelection selection)
      : quiet_(quiet), ndjson_(ndjson), selection_(std::move(selection)) {}
  // The steps go to the result file as they are reached (contact::io::ResultStream).
  void set_step_sink(contact::StepSink* sink) { sink_ = sink; }
  contact::StepSink* step_sink() override { return sink_; }
  void on_iteration(const contact::IterationReport& r) override {
    if (ndjson_) {
      nlohmann::json line = contact::io::bounded_progress(contact::io::iteration_json(r), selection_);
      line["type"] = "iteration";
      std::printf("%s\n", line.dump().c_str());
      std::fflush(stdout);
      return;
    }
    if (quiet_) return;
    const bool active_set = r.measure == contact::Measure::complementarity;
    std::printf("%s %4d", active_set ? "step" : "iter", r.iteration);
    if (r.update > 0) std::printf("  update %3d", r.update);
    if (active_set)
      std::printf("  active %4d (changed %3d)  complementarity %.3e", r.active_nodes, r.active_set_changes,
                  r.complementarity);
    else if (r.measure == contact::Measure::gradient)
      std::printf("  gradient %.3e  active %4d (changed %3d)", r.fixed_point_residual, r.active_nodes,
                  r.active_set_changes);
    else
      std::printf("  paper %.3e  residual %.3e", r.paper_criterion, r.fixed_point_residual);
    if (r.gamma > 0) std::printf("  gamma %.3g", r.gamma);
    print_pairs(contact::io::bounded_progress(contact::io::iteration_json(r, false), selection_));
    std::printf("  %.2fs", r.elapsed_seconds);
    if (!r.note.empty()) std::printf("  [%s]", r.note.c_str());
    std::printf("\n");
    std::fflush(stdout);
  }

  // Every pair while they are few (kPairsShown) and none is selected; otherwise the totals (with friction the
  // stick and slip counts), the pair of highest pressure, and the first kPairsShown of the pairs the job or
  // --progress-pairs selects, so that a line stays short on a wall of hundreds of pairs (the result file has
  // every pair).
  void print_pairs(const nlohmann::json& progress) const {
    const auto& pairs = progress["pairs"];
    auto print_pair = [](const nlohmann::json& p) {
      std::printf("  | %s: force %.6g  p_max %.6g  active %d (%+d)", p.value("name", "").c_str(), p.value("force", 0.0),
                  p.value("max_pressure", 0.0), p.value("active_nodes", 0), p.value("changed_nodes", 0));
      if (p.contains("stick_nodes"))
        std::printf("  stick %d slip %d", p.value("stick_nodes", 0), p.value("slip_nodes", 0));
    };
    const auto& s = progress["pairs_summary"];
    if (selection_.all || (selection_.patterns.empty() && s.value("count", 0) <= static_cast<int>(kPairsShown))) {
      for (const auto& p : pairs) print_pair(p);
      return;
    }
    std::printf("  | %d pairs: force %.6g  active %.0f (%.0f changed in %d pairs)", s.value("count", 0),
                s.value("force", 0.0), s.value("active_nodes", 0.0), s.value("changed_nodes", 0.0),
                s.value("pairs_changed", 0));
    if (s.value("friction_pairs", 0) > 0)
      std::printf("  stick %.0f slip %.0f", s.value("stick_nodes", 0.0), s.value("slip_nodes", 0.0));
    std::printf("  p_max %.6g at %s", s.value("max_pressure", 0.0), s.value("max_pressure_pair", "").c_str());
    std::size_t shown = 0, selected = 0;
    for (const auto& p : pairs)
      if (contact::io::matches_any(p.value("name", ""), selection_.patterns) && ++selected <= kPairsShown) {
        print_pair(p);
        ++shown;
      }
    if (selected > shown)
      std::printf("  | and %zu more selected pairs (--progress ndjson lists them)", selected - shown);
  }
  static constexpr size_t kPairsShown = 6;

  // One line per adaptive step: cells and unknowns per body (and the cells refined after the step), the global
  // estimate, force and peak pressure with their relative changes over the step (what the stop test compares),
  // the estimate's own time and the elapsed time.
  // One line per load step that held, cut and collapse trial (their own words: an iteration line is the solver's).
  void on_load_step(const contact::LoadStepReport& r) override {
    const nlohmann::json line = contact::io::load_step_json(r);
    if (ndjson_) {
      nlohmann::json out = line;
      out["type"] = "load_step";
      std::printf("%s\n", out.dump().c_str());
      std::fflush(stdout);
      return;
    }
    if (quiet_) return;
    std::printf("%s  %.2fs\n", contact::io::load_step_words(line).c_str(), r.elapsed_seconds);
    std::fflush(stdout);
  }

  void on_adaptive_step(const contact::AdaptiveStepReport& r) override {
    if (ndjson_) {
      nlohmann::json line = contact::io::adaptive_step_json(r);
      line["type"] = "adaptive_step";
      std::printf("%s\n", line.dump().c_str());
      std::fflush(stdout);
      return;
    }
    if (quiet_) return;
    std::printf("adaptive step %2d", r.step);
    for (const auto& b : r.bodies) {
      std::printf("  | %s: %d cells, %d unknowns", b.name.c_str(), b.elements, b.dofs);
      if (b.elements_refined > 0) std::printf(" (refining %d)", b.elements_refined);
    }
    if (!std::isfinite(r.estimate))  // cancelled while estimating
      std::printf("  | estimate cancelled  force %.6g  p_max %.6g", r.force, r.peak_pressure);
    else if (r.compared_with < 0)
      std::printf("  | estimate %.3e  force %.6g  p_max %.6g", r.estimate, r.force, r.peak_pressure);
    else {  // the changes the stop test reads, against the last step with at most half the unknowns
      std::printf(
          "  | estimate %.3e  force %.6g  p_max %.6g  | against step %d: force %.2g %%, p_max %.2g %%, zone "
          "%.2g %%",
          r.estimate, r.force, r.peak_pressure, r.compared_with, 100 * r.force_change, 100 * r.peak_change,
          100 * r.extent_change);
      if (r.stick_change > 0.0 || r.tangential_change > 1e-9)  // (a load-controlled T changes by rounding only)
        std::printf(", stick zone %.2g %%, tangential %.2g %%", 100 * r.stick_change, 100 * r.tangential_change);
    }
    if (std::isfinite(r.pressure_estimate)) std::printf("  pressure error ~%.3g %%", 100 * r.pressure_estimate);
    std::printf("  | estimating %.2fs  %.2fs\n", r.indicator_seconds, r.elapsed_seconds);
    std::fflush(stdout);
  }

 private:
  bool quiet_, ndjson_;
  contact::io::ProgressSelection selection_;
  contact::StepSink* sink_ = nullptr;
};

// Ranks other than 0 report nothing.
// The other ranks under MPI: no progress, and no step kept but the last (rank 0 writes the file).
class Silent final : public contact::Observer {
 public:
  void on_iteration(const contact::IterationReport&) override {}
  contact::StepSink* step_sink() override { return &discard_; }

 private:
  struct Discard final : contact::StepSink {
    void take(const contact::Step&) override {}
  } discard_;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open job file '" + path + "'");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// The summary lines of the last step: per pair its force, resultant, peak pressure and penetration (and friction),
// per supported body its reactions (per displacement condition, the components it prescribes, and the total).
void print_final_step(const contact::Step& step) {
  constexpr size_t kPairLines = 24;  // a wall's hundreds of pairs are in the result file
  for (size_t k = 0; k < step.pairs.size() && k < kPairLines; ++k) {
    const auto& p = step.pairs[k];
    double p_max = 0, penetration = 0;
    for (Eigen::Index j = 0; j < p.pressure.size(); ++j) {
      p_max = std::max(p_max, p.pressure[j]);
      penetration = std::max(penetration, p.penetration[j]);
    }
    if (p.enforcement == "exact")
      std::printf(
          "pair %s: exact contact, force %.8g, resultant (%.8g, %.8g), max pressure %.8g, max penetration %.4g\n",
          p.name.c_str(), p.force, p.resultant.x(), p.resultant.y(), p_max, penetration);
    else
      std::printf(
          "pair %s: %s, theta %.4g, force %.8g, resultant (%.8g, %.8g), max pressure %.8g, max penetration %.4g\n",
          p.name.c_str(), p.enforcement.c_str(), p.theta, p.force, p.resultant.x(), p.resultant.y(), p_max,
          penetration);
    if (p.friction != "none") {
      const long stick = p.stick.size() ? p.stick.cast<long>().sum() : 0, in_contact = p.active.cast<long>().sum();
      std::printf("pair %s: %s friction (%s %.4g), tangential force %.8g, %ld of %ld nodes in contact sticking\n",
                  p.name.c_str(), p.friction.c_str(), p.friction == "coulomb" ? "mu" : "bound",
                  p.friction == "coulomb" ? p.friction_coefficient : p.friction_bound, p.tangential_force, stick,
                  in_contact);
      // The joint as an engineer reads it (contact::JointResults; NaN where it does not apply).
      std::printf(
          "pair %s: as a joint: centre of pressure at %.6g along the slave edge (eccentricity %.3g of the "
          "half-length), "
          "%.3g open, %.3g slipping, friction utilisation %.3g\n",
          p.name.c_str(), p.joint.centre_of_pressure, p.joint.eccentricity, p.joint.open_fraction,
          p.joint.slip_fraction, p.joint.friction_utilisation);
    }
  }
  if (step.pairs.size() > kPairLines)
    std::printf("... and %zu more pairs (every pair is in the result file)\n", step.pairs.size() - kPairLines);
  for (const auto& b : step.bodies) {
    if (b.support_reactions.empty()) continue;
    std::printf("body %s: reactions total (%.8g, %.8g)", b.name.c_str(), b.reaction_total.x(), b.reaction_total.y());
    for (const auto& s : b.support_reactions)
      std::printf("; %s (%.8g, %.8g)", s.where.c_str(), s.force.x(), s.force.y());
    std::printf("\n");
  }
}

// The result file and its XDMF sidecar; throws what cannot be written.
std::string xmf_path_of(const std::string& output) {
  return std::filesystem::path(output).replace_extension(".xmf").string();
}

void write_files(contact::io::ResultStream& stream, const std::string& output, const contact::Problem& problem,
                 const contact::Result& result, const std::string& job_id, bool ndjson) {
  contact::io::WriteInfo info;
  info.job_id = job_id;
  stream.finish(problem, result, info);
  std::filesystem::path xmf = xmf_path_of(output);
  // ParaView's Xdmf3 readers abort on a bare file name (they join it with the data file's name): "./x.xmf".
  if (!xmf.has_parent_path()) xmf = std::filesystem::path(".") / xmf;
  if (!ndjson)
    std::printf("wrote %s and %s (in ParaView, open %s with the Xdmf3 Reader)\n", output.c_str(), xmf.string().c_str(),
                xmf.string().c_str());
}

// What the command says before solving: the job's shape, the method, and under MPI the ranks and placement.
void print_header(const contact::Session& session, const contact::Problem& problem) {
  std::printf("%s: %zu bodies, %zu contact pairs, method %s, enforcement %s\n", problem.name.c_str(),
              problem.bodies.size(), problem.contacts.size(), method_name(problem.solver.method),
              enforcement_name(problem.solver.enforcement));
  if (session.size() > 1) std::printf("%d MPI ranks (%s)\n", session.size(), session.placement(problem).c_str());
  std::fflush(stdout);
}

// Whether the method's outer loop counts active-set steps (else iterations), for the stop line.
bool counts_active_set_steps(const contact::Problem& problem) {
  const bool fixed_point =
      problem.solver.method == contact::Method::neumann || problem.solver.method == contact::Method::robin;
  const bool adaptive_paper =
      problem.adaptivity.enabled && problem.adaptivity.strategy == contact::AdaptStrategy::paper;
  return !fixed_point && !adaptive_paper &&
         (problem.solver.method == contact::Method::interface_newton ||
          problem.solver.enforcement == contact::Enforcement::exact);
}

// Everything after the job is parsed: solve on this process's share, report and write on rank 0. Returns the
// exit code (rank 0's decides for all).
void print_warning(const contact::Warning& w) {
  std::cerr << "warning: " << (w.pointer.empty() ? "" : w.pointer + ": ") << w.message << "\n";
}

int solve_and_write(contact::Session& session, contact::Problem& problem, const std::string& output,
                    const std::string& job_id, bool quiet, bool ndjson, contact::io::ProgressSelection selection) {
  const bool root = session.root();
  contact::CancelToken cancel;
  if (session.size() == 1) {
    g_direct_cancel = &cancel;
    if (g_stop_request) cancel.cancel();  // asked before the token existed
  }
  if (root && !ndjson) print_header(session, problem);
  ProgressPrinter printer(quiet, ndjson, std::move(selection));
  // The result file, written as the steps are reached (rank 0 only; an unfinished one is removed).
  contact::io::ResultStream stream(output, xmf_path_of(output), std::filesystem::path(output).filename().string());
  if (root) printer.set_step_sink(&stream);
  Silent silent;
  const contact::Result result =
      session.solve(problem, root ? static_cast<contact::Observer&>(printer) : silent, &g_stop_request, &cancel);
  g_direct_cancel = nullptr;
  const std::string traffic = session.traffic();
  if (!root) return 0;

  // The answer's warnings (after the job's, printed before the solve): on stderr, each with its pointer.
  for (size_t k = problem.warnings.size(); k < result.warnings.size(); ++k) print_warning(result.warnings[k]);
  if (!ndjson) {
    std::printf("stop: %s after %d %s, %.3f s (setup %.3f s): %s\n", contact::to_string(result.stop_reason),
                result.iterations, counts_active_set_steps(problem) ? "steps" : "iterations", result.wall_seconds,
                result.setup_seconds, result.message.c_str());
    if (!traffic.empty()) std::printf("mpi: %s\n", traffic.c_str());
  }
  nlohmann::json summary = {{"type", "result"},
                            {"stop_reason", contact::to_string(result.stop_reason)},
                            {"message", result.message},
                            {"converged", result.converged},
                            {"iterations", result.iterations},
                            {"wall_seconds", result.wall_seconds},
                            {"ranks", session.size()},
                            {"traffic", traffic},
                            {"result_written", false},
                            {"warnings", contact::warnings_json(result.warnings)},
                            {"collapse", contact::io::collapse_json(result.collapse)},
                            {"steps", nlohmann::json::array()}};
  auto finish = [&](int code) {
    if (ndjson) std::printf("%s\n", summary.dump().c_str());
    std::fflush(stdout);
    return code;
  };
  if (result.steps.empty()) {  // no file: nothing solved, or no step held and its iterate was not asked for
    const bool error = result.stop_reason == contact::StopReason::error;
    std::cerr << (error ? "error: " : "not converged, no result file: ") << result.message << "\n";
    return finish(error ? 1 : 3);
  }
  if (!ndjson) {
    // A solve that stopped short of convergence leaves the steps that held (and its last iterate, not an answer,
    // only if the job asked for it: output.iterate): said before the numbers of the last of them.
    if (!result.converged && result.steps.back().converged)
      std::printf("not converged: %s; below, the last of them (load factor %.6g)\n", result.kept.c_str(),
                  result.steps.back().load_factor);
    else if (!result.converged)
      std::printf("not converged: the last iterate, below and in the result file (converged 0), is not an answer\n");
    print_final_step(result.steps.back());
  }
  try {
    write_files(stream, output, problem, result, job_id, ndjson);
    summary["result_written"] = true;
    for (const auto& step : result.step_history) summary["steps"].push_back(contact::io::step_json(step));
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    summary["message"] = std::string("cannot write the result file: ") + e.what();
    return finish(1);
  }
  if (result.stop_reason == contact::StopReason::error) return finish(1);
  return finish(result.converged ? 0 : 3);
}

// Rank 0 reads the job file; every rank gets its text ("" and false when it cannot be read: the error is printed).
bool read_job(const contact::Session& session, const std::string& path, std::string& text) {
  int ok = 1;
  if (session.root()) {
    try {
      text = read_file(path);
    } catch (const std::exception& e) {
      std::cerr << "error: " << e.what() << "\n";
      ok = 0;
    }
  }
  if (!session.broadcast(ok)) return false;
  text = session.broadcast(text);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  catch_stop_signals();
  contact::Session session(&argc, &argv);
  CLI::App app{
      "contact-solve: contact of elastic bodies in 2D, frictionless or with friction, by domain decomposition (each\n"
      "body solved on its own).\n"
      "Methods (job field solver.method): interface_newton (default: exact dual-mortar contact, primal-dual active\n"
      "set on the bodies' interface Schur complements), neumann (the paper's penalty Neumann DDM (16)-(17)), robin,\n"
      "monolithic (reference).\n"
      "Friction (a contact's \"friction\"): Coulomb {\"coefficient\": mu} (|t| <= mu p) or Tresca {\"bound\": g}\n"
      "(|t| <= g), exact, by semismooth Newton on stick and slip (interface_newton or monolithic); incremental over\n"
      "the load steps; the result holds each pair's tangential traction, slip and stick nodes per step.\n"
      "See docs/job-format.md. Under `mpirun -n N` the bodies are spread over N ranks (docs/parallel.md).\n"
      "Exit codes: 0 converged; 1 solver or I/O error; 2 invalid job; 3 stopped without converging."};
  app.set_version_flag("--version", std::string("contact-solve ") + contact::solver_version());
  std::string job_path, output, job_id, progress = "text";
  bool validate_only = false, quiet = false;
  long max_dofs = contact::job::Limits{}.max_dofs;
  int threads = -1;
  app.add_option("job", job_path, "contact job (JSON, see docs/job-format.md)")->required();
  app.add_option("-o,--output", output, "result file (HDF5; default: the job file's name with .hdf)");
  app.add_flag("--validate", validate_only, "only validate the job and exit");
  bool strict = false;
  app.add_flag("--strict", strict,
               "warnings are errors: a job whose model checks warn (an undeclared overlap, a pair open everywhere) "
               "is invalid (exit 2), a solve whose answer warns (a body moved or turned far against its size) fails "
               "(exit 1, its result kept); as the job's \"strict\": true");
  app.add_flag("-q,--quiet", quiet, "no per-iteration lines");
  app.add_option("--max-dofs", max_dofs, "reject jobs with more unknowns than this")->check(CLI::PositiveNumber);
  double max_interface_bytes = -1;
  app.add_option("--max-interface-bytes", max_interface_bytes,
                 "reject jobs whose interface problem (method interface_newton) is estimated to take more memory "
                 "than this (default: this machine's memory; 0: no limit)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--threads", threads,
                 "threads for the per-body solves (per rank under mpirun; overrides the job; "
                 "0 = automatic)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--progress", progress,
                 "text (default): one line per iteration; ndjson: one JSON object per iteration and a final "
                 "\"result\" object, as contactd reads them (docs/parallel.md)")
      ->check(CLI::IsMember({"text", "ndjson"}));
  app.add_option("--job-id", job_id, "job id recorded in the result file (contactd sets it)");
  std::string progress_pairs;
  app.add_option("--progress-pairs", progress_pairs,
                 "the pairs whose detail each progress line lists: names or patterns (* ?) separated by commas, or "
                 "'all' (overrides the job's output.progress_pairs; default: every pair while there are few, else "
                 "the totals and the pairs that stand out)");
  bool keep_iterate = false;
  app.add_flag("--keep-iterate", keep_iterate,
               "when a step does not converge, keep its last iterate in the result file, flagged converged 0 (no "
               "answer: for diagnosis; as the job's output.iterate). Default: the steps that held only");
  bool no_mesh_files = false;
  app.add_flag("--no-mesh-files", no_mesh_files,
               "refuse Gmsh meshes given by file, as contactd does (it passes this flag): only \"data\"");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return session.root() ? app.exit(e) : (e.get_exit_code() == 0 ? 0 : 2);
  }
  const bool ndjson = progress == "ndjson";

  std::string text;
  if (!read_job(session, job_path, text)) return 2;
  contact::job::Limits limits;
  limits.max_dofs = max_dofs;
  limits.strict = strict;
  // A job that cannot fit is refused with the estimate, not started to be killed for memory (a long contact's dense
  // blocks grow with the square of its nodes).
  limits.max_interface_bytes = max_interface_bytes >= 0 ? max_interface_bytes
                                                        : static_cast<double>(sysconf(_SC_PHYS_PAGES)) *
                                                              static_cast<double>(sysconf(_SC_PAGE_SIZE));
  limits.interface_bytes_hint =
      max_interface_bytes >= 0 ? "--max-interface-bytes" : "this machine's memory; --max-interface-bytes sets another";
  // Gmsh mesh files are read relative to the job file's directory (by every rank).
  if (!no_mesh_files) limits.mesh_directory = contact::job::job_directory(job_path);
  auto parsed = contact::job::parse_text(text, limits);
  if (!parsed.ok()) {
    if (session.root())
      std::cerr << job_path << ": the job is invalid (" << parsed.errors.size() << " error"
                << (parsed.errors.size() == 1 ? "" : "s") << "):\n"
                << contact::job::format_errors(parsed.errors);
    return 2;
  }
  contact::Problem& problem = *parsed.problem;
  // The model checks' warnings (check/initial_gaps.hpp), before anything else is said of the job.
  if (session.root())
    for (const auto& w : problem.warnings) print_warning(w);
  if (threads >= 0) problem.solver.threads = threads;
  if (keep_iterate) problem.output.iterate = true;
  if (validate_only) {
    long dofs = 0;
    for (const auto& b : problem.bodies) dofs += 2L * b.mesh.num_nodes();
    if (session.root())
      std::cout << job_path << ": valid (" << problem.bodies.size() << " bodies, " << problem.contacts.size()
                << " contact pairs, " << dofs << " dofs before constraints"
                << (problem.warnings.empty() ? std::string()
                                             : ", " + std::to_string(problem.warnings.size()) + " warning" +
                                                   (problem.warnings.size() == 1 ? "" : "s") + " above")
                << ")\n";
    return 0;
  }
  if (output.empty()) output = std::filesystem::path(job_path).stem().string() + ".hdf";
  contact::io::ProgressSelection selection{problem.output.progress_pairs, false};
  if (progress_pairs == "all") {
    selection = {{}, true};
  } else if (!progress_pairs.empty()) {
    selection.patterns.clear();
    std::stringstream list(progress_pairs);
    for (std::string pattern; std::getline(list, pattern, ',');)
      if (!pattern.empty()) selection.patterns.push_back(pattern);
  }
  const int code =
      session.broadcast(solve_and_write(session, problem, output, job_id, quiet, ndjson, std::move(selection)));
  if (contact::background_work_running()) {
    // A cancel left a factorisation running (contact/solve.hpp); the result is written: exit now, not seconds later.
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    std::_Exit(code);
  }
  return code;
}
