// A job's record as the store persists it in state.json (JobRecord) and its states. The live job around it (cancel
// token, event log, locks) is jobs/job.hpp.
#pragma once

#include <nlohmann/json.hpp>

#include <memory>

#include <cstdint>
#include <optional>
#include <string>

namespace contactd {

enum class JobState { queued, running, succeeded, failed, cancelled };

const char* to_string(JobState state);                            // "QUEUED", ...
std::optional<JobState> job_state_from_string(std::string text);  // case-insensitive; nullopt if unknown
inline bool is_terminal(JobState s) {
  return s == JobState::succeeded || s == JobState::failed || s == JobState::cancelled;
}

// Everything state.json holds. Times are microseconds since the Unix epoch (0 = not yet).
struct JobRecord {
  std::string id;
  std::string name;  // the job's "name"
  JobState state = JobState::queued;
  std::int64_t created_us = 0, started_us = 0, finished_us = 0;
  int attempts = 0;             // runs started (a run interrupted by a restart or shutdown counts)
  int interruptions = 0;        // runs cut short by the server dying (found RUNNING at start-up)
  std::string idempotency_key;  // "" when none was given
  std::int64_t body_bytes = 0;
  // Small enough for the small-job lane (queue_settings.hpp, small_job); set at submission, changed only when a run
  // overran the lane and moved to the general one (while it is out of the queue).
  bool small = false;
  // The bytes its result is estimated to take (queue_settings.hpp, estimated_result); set at submission, never
  // changed. 0: not known (a record stored before the estimate was kept). The disk budget of the workers reads it.
  std::int64_t result_estimate = 0;
  // The outcome, set when the job is done.
  std::string stop_reason;  // converged, max_iterations, stagnation, cancelled, error, time_limit
  std::string message;
  std::optional<bool> converged;
  int iterations = 0;               // iterations of the last run so far
  double solve_seconds = 0.0;       // the solver's own wall time (Result::wall_seconds)
  bool result_available = false;    // result.hdf and result.xmf exist
  std::int64_t result_bytes = 0;    // the size of result.hdf as written (checked before it is served)
  std::int64_t events_dropped = 0;  // iteration events not recorded: the job's event log reached its cap
  // The model checks' warnings, [{"pointer", "message"}] (contact/warning.hpp): the job's at submission, the
  // run's (the job's and the answer's) once it is done.
  nlohmann::json warnings = nlohmann::json::array();
  // Once done: a collapse analysis's answer, or the statics' verdict on a step that failed (contact::io::
  // collapse_json: verdict, bracket, statics bound, mechanism); null for the others.
  nlohmann::json collapse;
  // The latest iteration in short (null before the first); shared, so copying a record (a listing, a snapshot)
  // does not copy it: a 500-body wall's is 0.6 MB.
  std::shared_ptr<const nlohmann::json> progress;
};

nlohmann::json to_state_json(const JobRecord& record);
// Throws std::runtime_error (nlohmann's errors included) when `j` is not a state document.
JobRecord from_state_json(const nlohmann::json& j);

}  // namespace contactd
