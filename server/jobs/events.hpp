// The fields of the progress events (docs/server.md, "Events"; api/openapi.yaml, components Event*). The same
// objects go out as Server-Sent Events and as NDJSON; EventLog adds seq, type and time.
#pragma once

#include "store/job_record.hpp"

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace contactd {

// "state": {"state": "QUEUED"|"RUNNING", "message": "...", "attempt": n}
nlohmann::json state_event(JobState state, const std::string& message, int attempt);

// "iteration": every field of the IterationReport, the pressure profile of every pair included.
nlohmann::json iteration_event(const contact::IterationReport& report);

// "step": one mesh state of the result: {"step", "iteration", "bodies": [{"name", "elements", "nodes"}]}.
nlohmann::json step_event(const contact::StepSummary& step);

// A job's progress (the last iteration event without its profiles) as the job list carries it, bounded whatever
// the job's size: up to kDigestItems pairs and bodies as they are; past that, instead of the array, its totals:
// "pairs_summary" {"count", "force", "active_nodes", "changed_nodes", "pairs_changed", "max_pressure",
// "max_pressure_pair"} and "bodies_summary" {"count", "elements", "dofs", "elements_refined"}. A 500-body wall's
// progress is 0.6 MB; its digest a few hundred bytes. GET /v1/jobs/{id} keeps the whole progress.
constexpr std::size_t kDigestItems = 6;
nlohmann::json progress_digest(const nlohmann::json& progress);

// "end": {"state", "stop_reason", "message", "converged", "iterations", "solve_seconds", "result_available"}.
nlohmann::json end_event(const JobRecord& record);

}  // namespace contactd
