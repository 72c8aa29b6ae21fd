// A job as the server keeps it in memory: its record (store/job_record.hpp, what state.json holds) and the live
// parts that exist only while the server runs: cancel token, event log, locks.
#pragma once

#include "jobs/event_log.hpp"
#include "store/job_record.hpp"

#include "contact/result.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace contactd {

// Why a running job's CancelToken was set; the first reason wins.
// `lane`: a small-lane run past --small-job-seconds, stopped to run again on a general worker.
enum class CancelReason : int { none = 0, user = 1, time_limit = 2, shutdown = 3, lane = 4 };

// A job in memory. `record`, `disk_bytes` and `cancelling_queued` are guarded by the JobRegistry's mutex;
// `deadline`, `lane_deadline`, `disk_wait` and `cancel_requested_at` by the WorkerPool's (the pool's lock is taken
// before the registry's, never after). persist_mutex serialises writes of state.json (a writer takes a snapshot of the
// record after locking it, so the last write carries the latest state).
struct Job {
  Job(JobRecord r, const std::string& events_path, std::uint64_t max_event_bytes)
      : record(std::move(r)), events(events_path, max_event_bytes) {}

  JobRecord record;
  contact::CancelToken cancel;
  std::atomic<int> cancel_reason{static_cast<int>(CancelReason::none)};
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  // A run on a small-lane worker past this is moved to the general lane (max: not on the small lane).
  std::chrono::steady_clock::time_point lane_deadline = std::chrono::steady_clock::time_point::max();
  std::string disk_wait;  // why the disk budget holds it back, as last put in its record ("" when it was not)
  EventLog events;
  std::mutex persist_mutex;
  std::atomic<bool> settled{false};  // done and its `end` event written: it may be deleted
  std::atomic<bool> stored{false};   // its files exist: visible to the API (a submission is stored first)
  std::int64_t disk_bytes = 0;       // what its directory holds once finished (retention)
  bool cancelling_queued = false;    // a cancel is storing this QUEUED job as CANCELLED

  // The last iteration's detail of every pair (profiles included) while the job runs: {"iteration", "pairs"}.
  // The events list only the pairs the job selects (contact/progress_json.hpp); GET /v1/jobs/{id}/pairs serves
  // any pair from here, and from pairs.json (the same, stored when the job ends) afterwards.
  void set_pair_detail(std::shared_ptr<const nlohmann::json> detail) {
    std::lock_guard<std::mutex> lock(detail_mutex_);
    pair_detail_ = std::move(detail);
  }
  std::shared_ptr<const nlohmann::json> pair_detail() const {
    std::lock_guard<std::mutex> lock(detail_mutex_);
    return pair_detail_;
  }

  // Called with the WorkerPool's mutex held.
  bool request_cancel(CancelReason reason) {
    int expected = static_cast<int>(CancelReason::none);
    const bool first = cancel_reason.compare_exchange_strong(expected, static_cast<int>(reason));
    if (first) cancel_requested_at = std::chrono::steady_clock::now();
    cancel.cancel();
    return first;
  }
  std::chrono::steady_clock::time_point cancel_requested_at{};  // when the first reason was set

 private:
  mutable std::mutex detail_mutex_;
  std::shared_ptr<const nlohmann::json> pair_detail_;
};

}  // namespace contactd
