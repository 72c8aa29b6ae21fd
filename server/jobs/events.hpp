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

// "end": {"state", "stop_reason", "message", "converged", "iterations", "solve_seconds", "result_available"}.
nlohmann::json end_event(const JobRecord& record);

}  // namespace contactd
