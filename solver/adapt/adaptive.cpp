#include "adaptive.hpp"

#include "../ddm/fixed_point.hpp"
#include "../ddm/load_steps.hpp"
#include "contact_zones.hpp"
#include "goal_marking.hpp"
#include "indicator.hpp"
#include "pressure_estimate.hpp"
#include "settled.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <utility>

namespace contact::adapt {

namespace {

// Doerfler's share for the goal-oriented marking: the cells holding half the pressure correction are refined.
// Measured on the two-cylinder example with a target of 0.1 %: 0.3 took more than 20 steps, 0.5 12 steps and
// 120k unknowns, 0.7 8 steps and 173k.
constexpr double kGoalShare = 0.5;

bool adapts(const AdaptivitySettings& s, size_t body) {
  return s.bodies.empty() || std::find(s.bodies.begin(), s.bodies.end(), static_cast<int>(body)) != s.bodies.end();
}

// Indicator of every adaptive body (empty vector for the others).
std::vector<IndicatorResult> estimate(const Problem& problem, const ddm::ContactSystem& system,
                                      const fem::LoadPoint& at, const ddm::Displacements& u,
                                      const ddm::Displacements& contact_loads, parallel::TaskRunner& runner,
                                      const std::function<bool()>& stop = {}) {
  std::vector<IndicatorResult> out(problem.bodies.size());
  const parallel::BodyShare share{[&](size_t a, parallel::Packer& p) {
                                    p.put(out[a].eta);
                                    p.put(out[a].note);
                                    p.put(out[a].seconds);
                                    p.put(out[a].error2);
                                    p.put(out[a].reference2);
                                    p.put(out[a].cancelled ? 1.0 : 0.0);
                                    p.put(out[a].bem_displacement);
                                    p.put(out[a].error2_cell);
                                  },
                                  [&](size_t a, parallel::Unpacker& in) {
                                    out[a].eta = in.get_vector();
                                    out[a].note = in.get_string();
                                    out[a].seconds = in.get_double();
                                    out[a].error2 = in.get_double();
                                    out[a].reference2 = in.get_double();
                                    out[a].cancelled = in.get_double() != 0.0;
                                    out[a].bem_displacement = in.get_vector();
                                    out[a].error2_cell = in.get_vector();
                                  }};
  runner.run_bodies(
      problem.bodies.size(),
      [&](size_t a) {
        if (!adapts(problem.adaptivity, a)) return;
        const Body& body = problem.bodies[a];
        const Normalization norm = problem.adaptivity.normalization;
        out[a] = problem.adaptivity.indicator == Indicator::fem_bem
                     ? fem_bem_indicator(body, problem.model, system.body(a), u[a], contact_loads[a], at, norm, stop)
                     : zz_indicator(body, system.body(a), u[a], norm);
      },
      share);
  return out;
}

struct RefineOutcome {
  std::vector<char> changed;
  std::vector<int> refined;  // cells split per body (closure included)
  std::vector<mesh::RefinementResult> refinements;
  std::string note;
  bool any = false;
  bool blocked = false;  // cells over delta were left unrefined by max_level or max_dofs
};

// Notes are joined by "; " (none before the first or after the last).
void add_note(std::string& notes, const std::string& note) {
  if (note.empty()) return;
  if (!notes.empty()) notes += "; ";
  notes += note;
}

// Refines `cells` (largest indicator first), halving the list until the refined mesh stays within `allowed`
// unknowns (2 x nodes): mark() keeps a margin for the 1-irregularity closure, which can still add more.
mesh::RefinementResult refine_within(mesh::Mesh& mesh, std::vector<int> cells, int max_level, long allowed,
                                     std::string& note, const std::string& body) {
  // Far from the limit (a split and its closure add well under 60 unknowns per marked cell): in place.
  if (2L * mesh.num_nodes() + 60L * static_cast<long>(cells.size()) <= allowed)
    return mesh::refine(mesh, cells, max_level);
  for (;;) {
    mesh::Mesh trial = mesh;
    mesh::RefinementResult r = mesh::refine(trial, cells, max_level);
    if (2L * trial.num_nodes() <= allowed) {
      mesh = std::move(trial);
      return r;
    }
    if (note.find("'" + body + "': max_dofs") == std::string::npos)
      add_note(note, "body '" + body + "': max_dofs reached, refinement cut back");
    if (cells.size() <= 1) return mesh::RefinementResult{};  // not even one split fits
    cells.resize(cells.size() / 2);
  }
}

// The marking of cells chosen elsewhere (the goal-oriented bulk marking), as mark() would report it: cells the
// grading keeps are left out, and the list is cut to the room mark() allows under `allowed`.
Marking chosen_marking(const std::vector<int>& chosen, const std::vector<char>& graded, const mesh::Mesh& mesh,
                       long allowed) {
  Marking m;
  for (const int c : chosen) {
    if (!graded.empty() && graded[static_cast<size_t>(c)])
      ++m.graded_out;
    else
      m.cells.push_back(c);
  }
  const long room = (allowed - 2L * mesh.num_nodes()) / 20;  // as mark() counts it
  if (static_cast<long>(m.cells.size()) > room) {
    m.dof_limit_hit = true;
    m.cells.resize(static_cast<size_t>(std::max(0L, room)));
  }
  return m;
}

// A refinement whose meshes would take the interface problem past the job's limit on its memory (method
// interface_newton: dense blocks over each body's contact unknowns, growing with the square of the contact edges'
// nodes) is undone, the meshes restored from `before`, and the run stops refining there with the reason.
void keep_interface_within(Problem& problem, std::vector<mesh::Mesh>& before, RefineOutcome& out) {
  const auto edge_nodes = [&](int body, const std::string& edge) {
    return static_cast<double>(problem.bodies[static_cast<size_t>(body)].mesh.edge_set_nodes(edge).size());
  };
  const InterfaceMemoryEstimate next = estimate_interface_memory(problem.contacts, problem.bodies.size(), edge_nodes);
  const double limit = problem.adaptivity.max_interface_bytes;
  if (next.bytes <= limit) return;
  for (size_t a = 0; a < problem.bodies.size() && a < before.size(); ++a)
    if (out.changed[a]) problem.bodies[a].mesh = std::move(before[a]);
  out.any = false;
  out.blocked = true;
  std::fill(out.changed.begin(), out.changed.end(), 0);
  std::fill(out.refined.begin(), out.refined.end(), 0);
  for (auto& r : out.refinements) r = {};
  const auto mb = [](double bytes) {  // as the job reader says it
    char text[32];
    std::snprintf(text, sizeof text, bytes >= 1e9 ? "%.3g GB" : "%.3g MB", bytes >= 1e9 ? bytes / 1e9 : bytes / 1e6);
    return std::string(text);
  };
  add_note(out.note, "the refined meshes' contact interface would take about " + mb(next.bytes) + " (body '" +
                         problem.bodies[next.body].name + "': " +
                         std::to_string(static_cast<long>(next.contact_nodes)) + " contact nodes), more than the " +
                         mb(limit) + " the job was admitted under (--max-interface-bytes): refinement stopped");
}

// Marks and refines the adaptive bodies; `step` is the current mesh state (its contact zones for the grading);
// `kept_nodes`: the nodes of the steps the result keeps besides the next mesh (StepLog::committed_nodes);
// `goal`: the cells to refine, chosen by the goal-oriented marking (with a target), instead of the indicator's
// over delta (nullptr).
RefineOutcome mark_and_refine(Problem& problem, const std::vector<IndicatorResult>& eta, const Step& step,
                              double kept_nodes, const BulkMarking* goal = nullptr) {
  const auto& s = problem.adaptivity;
  // The total the next mesh may have: the job's limit on unknowns, and what the result's budget leaves.
  long max_total = s.max_total_dofs;
  bool result_bound = false;
  if (s.max_kept_nodes > 0) {
    const long left = static_cast<long>(std::max(0.0, 2.0 * (s.max_kept_nodes - kept_nodes)));
    result_bound = max_total <= 0 || left < max_total;
    if (result_bound) max_total = left;
  }
  const std::vector<ContactZone> zones =
      s.marking != MarkingRule::plain ? contact_zones(step) : std::vector<ContactZone>{};  // (goal: for the grading)
  RefineOutcome out;
  const size_t n = problem.bodies.size();
  // With a limit on the interface's memory, the meshes as they were: restored if the refined ones would pass it.
  std::vector<mesh::Mesh> before;
  if (s.max_interface_bytes > 0)
    for (size_t a = 0; a < n; ++a) before.push_back(adapts(s, a) ? problem.bodies[a].mesh : mesh::Mesh());
  // The job's total: each body may grow by what the others leave (counted as 2 x nodes, as mark() does).
  long total = 0;
  for (const auto& body : problem.bodies) total += 2L * body.mesh.num_nodes();
  bool total_hit = false;
  out.changed.assign(n, 0);
  out.refined.assign(n, 0);
  out.refinements.resize(n);
  for (size_t a = 0; a < n; ++a) {
    if (!adapts(s, a) || eta[a].eta.size() == 0) continue;
    auto& mesh = problem.bodies[a].mesh;
    const ContactMarking rules = contact_marking(mesh, zones, s.grading);
    Eigen::VectorXd weighted = eta[a].eta;
    for (Eigen::Index c = 0; c < weighted.size(); ++c) weighted[c] *= rules.factor[static_cast<size_t>(c)];
    const long own = 2L * mesh.num_nodes();
    const long allowed =
        max_total > 0 || result_bound ? std::min(s.max_dofs, own + std::max(0L, max_total - total)) : s.max_dofs;
    Marking m = goal ? chosen_marking(goal->cells[a], rules.graded, mesh, allowed)
                     : mark(mesh, weighted, s.delta, s.max_level, allowed, rules.graded);
    if (m.dof_limit_hit && allowed < s.max_dofs)
      total_hit = true;
    else if (m.dof_limit_hit)
      add_note(out.note, "body '" + problem.bodies[a].name + "': max_dofs reached, refinement cut back");
    if (m.level_limit_hit) add_note(out.note, "body '" + problem.bodies[a].name + "': cells at max_level not refined");
    if (m.graded_out > 0)
      add_note(out.note, "body '" + problem.bodies[a].name + "': " + std::to_string(m.graded_out) +
                             " cells over delta already fine enough for the contact (grading)");
    out.blocked = out.blocked || m.dof_limit_hit || m.level_limit_hit || m.graded_out > 0;
    add_note(out.note, eta[a].note);
    if (m.cells.empty()) continue;
    out.refinements[a] = refine_within(mesh, m.cells, s.max_level, allowed, out.note, problem.bodies[a].name);
    if (out.refinements[a].refined_cells == 0) out.blocked = true;  // not one marked split fits the limit
    total += 2L * mesh.num_nodes() - own;
    out.refined[a] = out.refinements[a].refined_cells;
    out.changed[a] = out.refined[a] > 0;
    out.any = out.any || out.changed[a];
  }
  if (goal && goal->level_limit_hit) {
    add_note(out.note, "cells at max_level not refined (they carry part of the pressure's error)");
    out.blocked = true;
  }
  if (out.any && s.max_interface_bytes > 0) keep_interface_within(problem, before, out);
  if (total_hit && result_bound) {
    add_note(out.note,
             "the result's limit on its size (the steps kept, --max-result-bytes) reached, refinement "
             "cut back");
    out.blocked = true;
  } else if (total_hit) {
    add_note(out.note, "the job's limit of " + std::to_string(s.max_total_dofs) +
                           " unknowns over all bodies (--max-dofs) reached, refinement cut back");
    out.blocked = true;
  }
  return out;
}

// u transferred to the refined meshes (new nodes interpolated from their parents).
void transfer(ddm::Displacements& u, const Problem& problem, const RefineOutcome& r) {
  for (size_t a = 0; a < u.size(); ++a) {
    if (!r.changed[a]) continue;
    const Eigen::MatrixXd old =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>>(u[a].data(), u[a].size() / 2, 2);
    const Eigen::MatrixXd moved = mesh::transfer(old, r.refinements[a], problem.bodies[a].mesh.num_nodes());
    Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> rowmajor = moved;
    u[a] = Eigen::Map<Eigen::VectorXd>(rowmajor.data(), rowmajor.size());
  }
}

Step make_step(const ddm::ContactSystem& system, const ddm::RunState& state, const ddm::Displacements& u,
               const ddm::Pressures& z, int iteration, int index, const std::vector<IndicatorResult>& eta,
               const ddm::Pressures& q = {}) {
  Step st = z.empty() ? system.fields(u, iteration, state)
                      : system.fields(u, z, iteration, state, nullptr, q.empty() ? nullptr : &q);
  st.index = index;
  for (size_t a = 0; a < st.bodies.size() && a < eta.size(); ++a)
    if (eta[a].eta.size() == st.bodies[a].mesh.num_cells()) st.bodies[a].indicator_cell = eta[a].eta;
  return st;
}

// The global stress estimate of a step: sqrt of the summed ||sigma_R - sigma_F||^2 over the summed ||sigma_R||^2 of
// the adaptive bodies (reported; the stop test reads the answer instead: settled.hpp).
double global_estimate(const std::vector<IndicatorResult>& eta) {
  double error2 = 0.0, reference2 = 0.0;
  for (const auto& e : eta) {
    error2 += e.error2;
    reference2 += e.reference2;
  }
  return reference2 > 0.0 ? std::sqrt(error2 / reference2) : 0.0;
}

// What the steps so far read (settled.hpp) and their global estimates, one entry a step.
struct StepReadings {
  std::vector<AnswerReading> answers;
  std::vector<double> estimates;
};

// The step's report: its meshes, its answer's totals and their changes against the step the stop test compares it
// with (answer_changes: the last with at most half its unknowns; NaN before there is one).
AdaptiveStepReport step_report(int step, const Problem& working, const ddm::MethodOutcome& total,
                               const StepReadings& readings, const std::vector<IndicatorResult>& eta, double elapsed) {
  AdaptiveStepReport r;
  r.step = step;
  if (!total.history.empty()) r.bodies = total.history.back().bodies;
  for (auto& b : r.bodies) b.elements_refined = 0;
  if (r.bodies.size() != working.bodies.size()) {
    r.bodies.assign(working.bodies.size(), BodyReport{});
    for (size_t a = 0; a < r.bodies.size(); ++a) {
      r.bodies[a].name = working.bodies[a].name;
      r.bodies[a].elements = working.bodies[a].mesh.num_cells();
    }
  }
  const size_t k = static_cast<size_t>(step);
  for (const PairReading& p : readings.answers[k].pairs) {
    r.force += p.force;
    r.peak_pressure = std::max(r.peak_pressure, p.peak);
  }
  r.estimate = readings.estimates[k];
  const AnswerChanges c = answer_changes(readings.answers, k);
  r.compared_with = c.compared_with;
  r.force_change = c.force;
  r.peak_change = c.peak;
  r.extent_change = c.extent;
  r.stick_change = c.stick;
  r.tangential_change = c.tangential;
  r.estimate_change = std::nan("");
  if (c.compared_with >= 0) {
    const double before = readings.estimates[static_cast<size_t>(c.compared_with)];
    const double scale = std::max(std::abs(r.estimate), std::abs(before));
    r.estimate_change = scale > 0.0 ? std::abs(r.estimate - before) / scale : 0.0;
  }
  for (const auto& e : eta) r.indicator_seconds += e.seconds;
  r.elapsed_seconds = elapsed;
  return r;
}

// The target test (adaptivity.target_error): the message when the step's pressure estimate meets it, else "".
std::string target_met(const AdaptiveStepReport& r, const PressureEstimate& pe, double target) {
  if (target <= 0.0 || !(pe.relative <= target)) return "";
  std::ostringstream os;
  os.precision(2);
  os << "adaptive: target met after " << r.step << " refinement steps: the estimated pressure error "
     << 100 * pe.relative << " % (boundary-element correction " << 100 * pe.defect << " %, contact edges "
     << 100 * pe.edges << " %";
  if (pe.stick_slip > 0.0) os << ", stick-slip points " << 100 * pe.stick_slip << " %";
  os << ") is at most target_error = " << 100 * target << " %";
  return os.str();
}

// What a stop other than the target says about the target, when the job set one.
std::string target_missed(const PressureEstimate& pe, double target) {
  if (target <= 0.0) return "";
  std::ostringstream os;
  os.precision(2);
  os << "; target_error = " << 100 * target << " % not reached: ";
  if (std::isfinite(pe.relative))
    os << "the last step's estimated pressure error is " << 100 * pe.relative << " %";
  else
    os << pe.note;
  return os.str();
}

// A run that stops refining before its pressure estimate meets the job's target_error has not done what the job
// asked: its answer is kept (every step converged), but it is not SUCCEEDED. It stops as a solve that did not
// converge: max_iterations where max_steps ended it, stagnation where the stop test or the meshes did (nothing
// left to refine, the unknowns' limit), so that the command line exits 3 and the server says FAILED with that
// reason and the estimate reached (docs/job-format.md, "A target").
bool target_missed_at_stop(const AdaptivitySettings& s, const PressureEstimate& pe) {
  return s.target_error > 0.0 && !(pe.relative <= s.target_error);
}

void miss_target(ddm::MethodOutcome& total, StopReason reason) {
  total.converged = false;
  total.stop_reason = reason;
}

// Marks and refines. With marking "goal" (the default where the pressure estimate can be made) or a target, by the
// share each cell has in the pressure
// estimate's correction (goal_marking.hpp): Doerfler's bulk marking of the cells that hold half of it; otherwise,
// or where the step has no pressure correction (the estimate failed), by the indicator over delta with the job's
// marking rule ("goal" then marks as "contact"). The
// indicator over delta with the contact rules spends its cells on the contact surface and its neighbourhood,
// where the stress error is large, while the pressure may be wrong because of the far field: on the two-cylinder
// example the far field makes the bodies 0.23 % too stiff and that marking stalled at 0.29 % for 14 steps
// (docs/algorithm.md, "Refinement for the pressure's target").
RefineOutcome refine_for_step(Problem& working, const ddm::ContactSystem& system,
                              const std::vector<IndicatorResult>& eta, const PressureEstimate& pe, const Step& step,
                              double kept_nodes, parallel::TaskRunner& runner) {
  const auto& s = working.adaptivity;
  const bool goal_oriented = s.target_error > 0.0 || s.marking == MarkingRule::goal;
  if (!goal_oriented || pe.correction.empty()) return mark_and_refine(working, eta, step, kept_nodes);
  // (The cells of the bulk the grading keeps are dropped after the choice, not left out of it: chosen among the
  // others, the bulk of Cattaneo-Mindlin under grading 0.5 was two or three cells a step for 30 steps; dropped, the
  // run ends at once, saying the cells the pressure's error asks for are kept coarse by the grading.)
  const BulkMarking goal =
      bulk_marking(working, goal_indicator(working, system, pe, eta, runner), kGoalShare, s.max_level);
  return mark_and_refine(working, eta, step, kept_nodes, &goal);
}

bool any_cancelled(const std::vector<IndicatorResult>& eta) {
  for (const auto& e : eta)
    if (e.cancelled) return true;
  return false;
}

// One solve on the current meshes in a frame nested in `frame` (its first report carries the elements refined
// before it); returns the total, whose answer and stop are now this solve's. With load steps (`path`: more than
// one factor) the whole path is solved from rest on these meshes and the answer is its end's: friction depends on
// the path, so each mesh state is the path's solution on that mesh, its history never transferred between
// meshes (docs/algorithm.md, "Adaptivity with friction"); the path's steps before the end are not kept.
const ddm::MethodOutcome& solve_step(ddm::ContactSystem& system, ddm::RunFrame& frame, ddm::ContactMethod& method,
                                     std::vector<int>& refined_last, const ddm::Displacements& warm,
                                     const std::vector<double>& path) {
  const ddm::InnerMarks marks{0, std::exchange(refined_last, {})};
  if (path.size() > 1) {
    ddm::StepLog path_steps(StepOutput::last, false);
    return frame.nested(nullptr, marks,
                        [&](ddm::RunFrame& inner) { ddm::run_load_steps(system, path, inner, method, path_steps); });
  }
  return frame.nested(warm.empty() ? nullptr : &warm, marks,
                      [&](ddm::RunFrame& inner) { ddm::run_enforced(system, inner, method); });
}

void mark_cancelled(ddm::MethodOutcome& total) {
  total.stop_reason = StopReason::cancelled;
  total.converged = false;
}

// The refined meshes take the solution (transferred) and are assembled and factorised; false, with the total's
// stop and message set, if a cancel or an error ended that.
bool rebuild_refined(Problem& working, ddm::ContactSystem& system, ddm::RunFrame& frame, ddm::ContactMethod& method,
                     const RefineOutcome& r, int step, ddm::Displacements& warm) {
  ddm::MethodOutcome& total = frame.outcome();
  transfer(warm, working, r);
  system.rebuild(r.changed, frame.state(), frame.stop_check());
  method.reset();
  if (system.cancelled()) {  // during the refined meshes' assembly or factorisation: they are not solved
    mark_cancelled(total);
    total.message = "cancelled during adaptive step " + std::to_string(step + 1) +
                    " (assembling and factorising its refined meshes; the result holds step " + std::to_string(step) +
                    "'s solution)";
    return false;
  }
  if (!system.ok()) {
    total.stop_reason = StopReason::error;
    total.converged = false;
    total.message = "adaptive: " + system.error();
    return false;
  }
  return true;
}

// The stops after a converged step's estimate, in order: the target, the stop test, max_steps; "" to go on.
std::string stop_after_estimate(const AdaptivitySettings& s, const AdaptiveStepReport& report,
                                const StepReadings& readings, const PressureEstimate& pe, int step,
                                const std::string& solve_message) {
  if (std::string met = target_met(report, pe, s.target_error); !met.empty()) return met;
  const std::string missed = target_missed(pe, s.target_error);
  if (const std::string stop = answer_settled(readings.answers, static_cast<size_t>(step), s.stop_tolerance);
      !stop.empty())
    return stop + missed;
  if (step >= s.max_steps)
    return "adaptive: max_steps = " + std::to_string(s.max_steps) + " refinement steps done" + missed + "; " +
           solve_message;
  return "";
}

// The step's pressure estimate. It solves each body alone with its factorisation, which the monolithic method
// does not build (one global system instead): there it is not made, and says why (the job reader refuses a
// target with that method; a Problem built in code meets it here).
PressureEstimate step_pressure_estimate(const ddm::ContactSystem& system, ddm::RunFrame& frame,
                                        const ddm::MethodOutcome& o, const std::vector<IndicatorResult>& eta) {
  if (frame.settings().method == Method::monolithic) {
    PressureEstimate none;
    none.relative = std::nan("");
    none.note = "no pressure estimate: it solves each body alone, and the monolithic method factorises none";
    return none;
  }
  return pressure_estimate(system, frame.state().load, o.u,
                           o.z.empty() ? system.penalty_pressures(o.u, frame.state()) : o.z, eta, frame.stop_check(),
                           o.q.empty() ? nullptr : &o.q);
}

// Solve, estimate, report the step, and stop (target, stop test, max_steps, nothing refinable, cancellation) or
// refine.
void converge_then_refine(Problem& working, ddm::ContactSystem& system, ddm::RunFrame& frame,
                          ddm::ContactMethod& method, ddm::StepLog& steps) {
  const auto& s = working.adaptivity;
  ddm::MethodOutcome& total = frame.outcome();
  std::vector<int> refined_last;
  ddm::Displacements warm;
  StepReadings readings;
  const std::string cancelled_here = "cancelled during adaptive step ";
  for (int step = 0;; ++step) {
    const ddm::MethodOutcome& o = solve_step(system, frame, method, refined_last, warm, working.loading.factors);
    if (o.u.empty()) return;
    if (frame.stop_requested()) {  // stopped inside the solve: keep what it reached, skip the estimate
      Step reached = make_step(system, frame.state(), o.u, o.z, total.iterations, step, {}, o.q);
      reached.converged = false;
      steps.push_back(std::move(reached));
      mark_cancelled(total);
      return;
    }
    // The whole contact traction, the tangential one too where there is friction, is the bodies' Neumann data.
    const ddm::Displacements loads = o.z.empty() ? system.contact_loads(o.u, frame.state())
                                                 : system.loads_from_pressures(o.z, o.q.empty() ? nullptr : &o.q);
    const auto eta = estimate(working, system, frame.state().load, o.u, loads, frame.runner(), frame.stop_check());
    for (const auto& e : eta) total.indicator_seconds += e.seconds;
    Step solved = make_step(system, frame.state(), o.u, o.z, total.iterations, step, eta, o.q);
    solved.converged = o.converged;
    readings.answers.push_back(read_answer(solved));
    readings.estimates.push_back(global_estimate(eta));
    steps.push_back(std::move(solved));  // an unconverged one only if the job asks for its iterate (StepLog)
    AdaptiveStepReport report = step_report(step, working, total, readings, eta, frame.elapsed());
    const auto finish = [&](const std::string& message) {
      if (!message.empty()) total.message = message;
      frame.report(report);
    };
    if (frame.stop_requested() || any_cancelled(eta)) {
      if (any_cancelled(eta)) report.estimate = report.estimate_change = std::nan("");  // only partly estimated
      report.pressure_estimate = std::nan("");
      mark_cancelled(total);
      return finish(cancelled_here + std::to_string(step) + " (the result holds that step's solution)");
    }
    const PressureEstimate pe = step_pressure_estimate(system, frame, o, eta);
    report.pressure_estimate = pe.relative;
    if (!o.converged) return finish("");
    if (const std::string stop = stop_after_estimate(s, report, readings, pe, step, o.message); !stop.empty()) {
      const bool settled = !answer_settled(readings.answers, static_cast<size_t>(step), s.stop_tolerance).empty();
      if (target_missed_at_stop(s, pe))
        miss_target(total, step >= s.max_steps && !settled ? StopReason::max_iterations : StopReason::stagnation);
      return finish(stop);
    }
    RefineOutcome r = refine_for_step(working, system, eta, pe, steps.back(), steps.committed_nodes(), frame.runner());
    if (!r.any) {
      std::ostringstream os;
      os << "adaptive: " << (r.blocked ? "nothing marked can be refined" : "no cell marked") << " after " << step
         << " refinement steps (" << (r.note.empty() ? "" : r.note + "; ") << "last solve: " << o.message << ")"
         << target_missed(pe, s.target_error);
      if (target_missed_at_stop(s, pe)) miss_target(total, StopReason::stagnation);
      return finish(os.str());
    }
    if (frame.stop_requested()) {  // during the marking and refinement: the refined meshes are not solved
      mark_cancelled(total);
      return finish(cancelled_here + std::to_string(step) + " (the result holds that step's solution)");
    }
    for (size_t a = 0; a < report.bodies.size() && a < r.refined.size(); ++a)
      report.bodies[a].elements_refined = r.refined[a];
    frame.report(report);
    warm = o.u;
    refined_last = r.refined;
    if (!rebuild_refined(working, system, frame, method, r, step, warm)) return;
  }
}

// The paper's (17) with relaxation gamma, and both stopping measures of the step from u to u_tilde: the paper's
// criterion (the zone normals' relative change over u -> u_new) and the fixed-point residual.
struct RelaxedUpdate {
  ddm::Displacements u_new;
  double residual = 0.0, paper = 0.0;
};

RelaxedUpdate relaxed_update(const ddm::ContactSystem& system, const ddm::Displacements& u,
                             const ddm::Displacements& u_tilde, double gamma) {
  RelaxedUpdate out;
  out.u_new.resize(u.size());
  double diff2 = 0, base2 = 0;
  for (size_t a = 0; a < u.size(); ++a) {
    const Eigen::VectorXd z = system.zone_normals(a, u[a]), zt = system.zone_normals(a, u_tilde[a]);
    diff2 += (zt - z).squaredNorm();
    base2 += std::max(z.squaredNorm(), zt.squaredNorm());
    out.u_new[a] = gamma * u_tilde[a] + (1 - gamma) * u[a];
    out.paper = std::max(out.paper, ddm::relative_change(system.zone_normals(a, out.u_new[a]), z));
  }
  out.residual = base2 > 0 ? std::sqrt(diff2 / base2) : 0.0;
  return out;
}

// gamma: the job's, or with "auto" from the Neumann map's spectral radius (as the fixed-point methods choose it).
double paper_gamma(const ddm::ContactSystem& system, const ddm::RunFrame& frame, int& solves_per_body) {
  const SolverSettings& settings = frame.settings();
  if (!settings.gamma_auto) return settings.gamma;
  ddm::NeumannMap map(system, frame.state(), frame.runner());
  int solves = 0;
  const double gamma = std::min(1.0, 1.8 / (2.0 + ddm::estimate_spectral_radius(system, map, 12, solves)));
  solves_per_body += solves;
  return gamma;
}

// After a refinement: the iterate carried to the new meshes and the system rebuilt on them. An empty message when
// it went well, else why the loop stops (the reason in `reason`).
std::string rebuild_after_refinement(Problem& working, ddm::ContactSystem& system, ddm::RunFrame& frame,
                                     const RefineOutcome& r, ddm::Displacements& u, StopReason& reason) {
  transfer(u, working, r);
  system.rebuild(r.changed, frame.state(), frame.stop_check());
  if (system.cancelled()) {
    reason = StopReason::cancelled;
    return "cancelled during the refined meshes' assembly and factorisation (the result holds the steps before)";
  }
  if (!system.ok()) {
    reason = StopReason::error;
    return "adaptive: " + system.error();
  }
  return "";
}

// The paper's interleaving: one Neumann update (16)-(17), then estimate and refine, every iteration; it stops when
// the DDM criterion holds and no cell is marked.
void paper_interleaving(Problem& working, ddm::ContactSystem& system, ddm::RunFrame& frame, ddm::StepLog& steps) {
  const SolverSettings& settings = frame.settings();
  ddm::MethodOutcome& out = frame.outcome();
  ddm::Displacements u = ddm::initial_iterate(system, frame, out.subdomain_solves);
  out.gamma = paper_gamma(system, frame, out.subdomain_solves);
  std::vector<std::vector<char>> active;
  int step = 0;
  for (int k = 1; k <= settings.max_iterations; ++k) {
    if (frame.stop_requested()) {
      out.stop_reason = StopReason::cancelled;
      out.message = "cancelled";
      break;
    }
    // (16) on the current meshes, then (17); the estimate on the body solutions of (16) with the contact tractions
    // they were solved with.
    const ddm::Displacements loads = system.contact_loads(u, frame.state());
    const ddm::Displacements u_tilde = system.solve_bodies(loads, frame.state().load);
    ++out.subdomain_solves;
    RelaxedUpdate update = relaxed_update(system, u, u_tilde, out.gamma);
    const bool ddm_converged =
        (settings.criterion == Criterion::paper ? update.paper : update.residual) <= settings.tolerance;
    const auto eta =
        estimate(working, system, frame.state().load, u_tilde, loads, frame.runner());  // (not stopped within)
    for (const auto& e : eta) out.indicator_seconds += e.seconds;
    IterationReport rep = system.report(k, update.u_new, frame.state(), active);
    rep.paper_criterion = update.paper;
    rep.fixed_point_residual = update.residual;
    rep.gamma = out.gamma;
    // Record the mesh state (before it is refined), then refine.
    Step st = make_step(system, frame.state(), update.u_new, {}, k, step, eta);
    double mesh_nodes = 0;  // st is kept (pushed below) if the meshes are refined
    for (const auto& body : st.bodies) mesh_nodes += static_cast<double>(body.mesh.num_nodes());
    const RefineOutcome r =
        mark_and_refine(working, eta, st, steps.committed_nodes() + (steps.keeps_all() ? mesh_nodes : 0.0));
    for (size_t a = 0; a < rep.bodies.size(); ++a) rep.bodies[a].elements_refined = r.refined[a];
    rep.note = r.note;
    frame.report(std::move(rep));
    out.iterations = k;
    u = std::move(update.u_new);
    if (!r.any && ddm_converged) {
      steps.push_back(std::move(st));
      out.converged = true;
      out.stop_reason = StopReason::converged;
      out.message = "adaptive (paper): the DDM criterion holds and " +
                    std::string(r.blocked ? "nothing marked can be refined" : "no cell is marked") + " (" +
                    std::to_string(step) + " refinements" + (r.blocked && !r.note.empty() ? "; " + r.note : "") + ")";
      break;
    }
    if (r.any) {
      steps.push_back(std::move(st));
      ++step;
      out.message = rebuild_after_refinement(working, system, frame, r, u, out.stop_reason);
      if (!out.message.empty()) break;
    }
    if (!std::isfinite(update.residual)) {
      out.stop_reason = StopReason::error;
      out.message = "the iteration diverges; reduce gamma";
      break;
    }
    if (k == settings.max_iterations) {
      out.stop_reason = StopReason::max_iterations;
      out.message = "adaptive (paper): max_iterations reached";
      Step reached = make_step(system, frame.state(), u, {}, k, step, {});
      reached.converged = false;
      steps.push_back(std::move(reached));
    }
  }
  out.u = std::move(u);
}

}  // namespace

void run_adaptive(Problem& working, ddm::ContactSystem& system, ddm::RunFrame& frame, ddm::ContactMethod& method,
                  ddm::StepLog& steps) {
  if (working.adaptivity.strategy == AdaptStrategy::paper) return paper_interleaving(working, system, frame, steps);
  converge_then_refine(working, system, frame, method, steps);
}

}  // namespace contact::adapt
