// A job as the server keeps it: the record persisted in state.json (JobRecord) and the live parts that exist only
// while the server runs (Job: cancel token, event log, locks).
#pragma once

#include "event_log.hpp"

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
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
  // The outcome, set when the job is done.
  std::string stop_reason;  // converged, max_iterations, stagnation, cancelled, error, time_limit
  std::string message;
  std::optional<bool> converged;
  int iterations = 0;             // iterations of the last run so far
  double solve_seconds = 0.0;     // the solver's own wall time (Result::wall_seconds)
  bool result_available = false;  // result.hdf and result.xmf exist
  std::int64_t result_bytes = 0;  // the size of result.hdf as written (checked before it is served)
  std::int64_t events_dropped = 0;  // iteration events not recorded: the job's event log reached its cap
  nlohmann::json progress;        // the latest iteration in short (null before the first)
};

nlohmann::json to_state_json(const JobRecord& record);
// Throws std::runtime_error (nlohmann's errors included) when `j` is not a state document.
JobRecord from_state_json(const nlohmann::json& j);

// Why a running job's CancelToken was set; the first reason wins.
enum class CancelReason : int { none = 0, user = 1, time_limit = 2, shutdown = 3 };

// A job in memory. `record` is guarded by the JobQueue's mutex; persist_mutex serialises writes of state.json
// (a writer takes a snapshot of the record after locking it, so the last write carries the latest state).
struct Job {
  Job(JobRecord r, const std::string& events_path, std::uint64_t max_event_bytes)
      : record(std::move(r)), events(events_path, max_event_bytes) {}

  JobRecord record;
  contact::CancelToken cancel;
  std::atomic<int> cancel_reason{static_cast<int>(CancelReason::none)};
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  EventLog events;
  std::mutex persist_mutex;
  std::atomic<bool> settled{false};  // done and its `end` event written: it may be deleted
  std::atomic<bool> stored{false};   // its files exist: visible to the API (a submission is stored first)
  std::int64_t disk_bytes = 0;       // what its directory holds once finished (retention); the queue's mutex
  bool cancelling_queued = false;    // a cancel is storing this QUEUED job as CANCELLED; the queue's mutex

  // Called with the queue's mutex held.
  bool request_cancel(CancelReason reason) {
    int expected = static_cast<int>(CancelReason::none);
    const bool first = cancel_reason.compare_exchange_strong(expected, static_cast<int>(reason));
    if (first) cancel_requested_at = std::chrono::steady_clock::now();
    cancel.cancel();
    return first;
  }
  std::chrono::steady_clock::time_point cancel_requested_at{};  // when the first reason was set
};

}  // namespace contactd
