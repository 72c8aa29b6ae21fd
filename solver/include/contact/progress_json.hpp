// Progress as JSON: one object per solver iteration and per result step. The server streams these as its
// `iteration` and `step` events (docs/server.md, "Events"), and `contact-solve --progress ndjson` prints them one
// per line, which is how the server follows a job that runs under mpirun.
//
// What a progress object lists is bounded whatever the job's size (a 64 x 64 wall has 8,000 pairs; every pair's
// profiles are megabytes per iteration): bounded_progress() adds the totals ("pairs_summary", "bodies_summary")
// and lists every pair only while there are few; past that, the pairs the job selects
// (output.progress_pairs) and the two a reader needs to see first: the one with the highest pressure and the one
// whose contact nodes changed most. The result file has every pair.
#pragma once

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace contact::io {

// Every field of the report, every pair and body; the per-node profiles (positions, pressures and, with friction,
// tangential_tractions and stick) only with `profiles`.
nlohmann::json iteration_json(const IterationReport& report, bool profiles = true);

// One adaptive step (AdaptiveStepReport) as an object without "type": the step, the bodies' cells, unknowns and
// cells refined after it, the global stress estimate, the estimated pressure error (null where it cannot be
// made), force and peak pressure, their relative changes over the step, and the times. contact-solve's
// --ndjson "adaptive_step" lines and contactd's "adaptive_step" events.
nlohmann::json adaptive_step_json(const AdaptiveStepReport& report);

// A load step's end, a cut or a collapse trial (LoadStepReport): {"kind": "held" | "cut" | "trial", "step",
// "steps", "fraction", "next" (a cut), "load_factor", "multiplier" and "held" (a trial), "iterations",
// "elapsed_seconds"}, as contactd's `load_step` events and contact-solve --progress ndjson carry it.
nlohmann::json load_step_json(const LoadStepReport& report);

// The same in words, one line: "load step 2 of 4 held at load factor 0.5 (12 iterations)", "load step 2 of 4 cut:
// held to 25 % of the step, now trying 37.5 %", "collapse trial 3: multiplier 0.45 held (13 iterations)".
std::string load_step_words(const nlohmann::json& event);

// Which pairs a bounded progress object lists in full.
struct ProgressSelection {
  std::vector<std::string> patterns;  // shell globs on pair names (fnmatch: * ? [..]); empty: the default
  bool all = false;                   // every pair whatever their number (contactd asks its MPI runs for this)
};
inline constexpr std::size_t kPairsListedAll = 16;    // by default, up to this many pairs every pair is listed
inline constexpr std::size_t kMaxPairsSelected = 64;  // at most this many pairs matched by the patterns are listed
inline constexpr std::size_t kBodiesListedAll = 64;   // past this many bodies only their totals

bool matches_any(const std::string& name, const std::vector<std::string>& patterns);

// The totals of an iteration's "pairs" array: {"count", "force", "tangential_force", "active_nodes",
// "changed_nodes" (sum of |changed|), "pairs_changed", "friction_pairs", "stick_nodes", "slip_nodes",
// "max_pressure", "max_pressure_pair", "most_changed_pair", "most_changed_nodes", "max_penetration"}; the pair
// names are "" when no pair qualifies.
nlohmann::json pairs_summary(const nlohmann::json& pairs);
// The totals of its "bodies" array: {"count", "elements", "dofs", "elements_refined"}.
nlohmann::json bodies_summary(const nlohmann::json& bodies);

// `full` (iteration_json) with "pairs_summary" and "bodies_summary" added and its lists bounded: "pairs" keeps
// every pair when selection.all, or when there are at most kPairsListedAll and no patterns; otherwise the pairs
// the patterns match (the first kMaxPairsSelected in the job's order) and the summary's max_pressure_pair and
// most_changed_pair, in the job's order; "pairs_listed" says which ("all" or "selected"). "bodies" is dropped past
// kBodiesListedAll bodies ("bodies_listed": "all" or "none").
nlohmann::json bounded_progress(nlohmann::json full, const ProgressSelection& selection);

// One step of the result (Result::step_history: every step, whether its fields are kept or not):
// {"step", "iteration", "bodies": [{"name", "elements", "nodes"}]}.
nlohmann::json step_json(const StepSummary& step);

// A collapse analysis's answer, or a failed step's statics verdict (Result::collapse), as the server's job and end
// event and contact-solve's summary give it: {"verdict", "held", "failed", "statics_bound", "solves", "words",
// "mechanism": {"kind", "words", "bodies", "joints"}, ...}; null when there is none.
nlohmann::json collapse_json(const CollapseResult& c);

}  // namespace contact::io
