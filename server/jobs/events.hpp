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

// "step": one mesh state of the result: {"step", "iteration", "bodies_summary", "bodies": [{"name", "elements",
// "nodes"}] (while there are at most contact::io::kBodiesListedAll bodies)}.
nlohmann::json step_event(const contact::StepSummary& step);

// A job's progress (the last iteration event without its profiles) as the job list carries it, smaller still
// than the event: up to kDigestItems pairs and bodies as they are; past that only their totals ("pairs_summary",
// "bodies_summary", contact/progress_json.hpp). GET /v1/jobs/{id} keeps the event's lists.
constexpr std::size_t kDigestItems = 6;
nlohmann::json progress_digest(const nlohmann::json& progress);

// "end": {"state", "stop_reason", "message", "converged", "iterations", "solve_seconds", "result_available"}.
nlohmann::json end_event(const JobRecord& record);

}  // namespace contactd
