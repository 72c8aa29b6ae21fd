// The jobs the server knows: every job's record and how it is found (by id, by creation time, by idempotency
// key), the counts by state, the finished jobs in the order retention deletes them, and the damage found in the
// store.
//
// Every state change the API reports is on disk first: commit() writes the new record to state.json, and only
// then does the job in memory change. A write that fails leaves the job as it was (the caller reports the store
// error).
//
// Damage found in the store (a state.json that cannot be read, an event log or result file changed on disk) is
// kept here: such jobs are never served from their files nor deleted by retention, and damaged() lists them for
// /readyz and /metrics.
//
// Thread safety: every public member may be called from any thread. One mutex guards the registry and every
// job's record (Job::record, disk_bytes, cancelling_queued); it is never held while writing files or waiting for
// a client. It may be taken while the WorkerPool's mutex is held, never the other way round.
#pragma once

#include "jobs/job.hpp"
#include "metrics/metrics.hpp"
#include "store/job_store.hpp"

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace contactd {

class JobRegistry {
 public:
  using Change = std::function<void(JobRecord&)>;

  JobRegistry(JobStore& store, std::uint64_t max_event_log_bytes);
  JobRegistry(const JobRegistry&) = delete;
  JobRegistry& operator=(const JobRegistry&) = delete;

  // A job in memory for `record` (not registered); damage its event log finds is reported here.
  std::shared_ptr<Job> make_job(const JobRecord& record);

  // What a submission finds: the job of its idempotency key, or room for a new job (registered, invisible to the
  // API until it is stored: `persisting` holds its persist lock, so that anyone persisting it waits for its files).
  struct Admission {
    enum class Outcome { admitted, existing, key_damaged, unavailable, queue_full };
    Outcome outcome = Outcome::admitted;
    std::shared_ptr<Job> job;                 // admitted: the new job; existing: the key's job
    bool same_body = false;                   // existing: submitted with the same body
    std::string damaged_id;                   // key_damaged: the id of the key's job
    std::unique_lock<std::mutex> persisting;  // admitted
  };
  // With a key already used: existing (or key_damaged); otherwise unavailable when `stopping`, queue_full with
  // `max_queued` jobs QUEUED, else a new QUEUED job named `name` is admitted.
  Admission admit(const std::string& name, const std::string& idempotency_key, std::size_t body_hash,
                  std::int64_t body_bytes, bool stopping, std::size_t max_queued);
  // Takes an admitted job out again (its files could not be created).
  void forget(const std::shared_ptr<Job>& job);
  // A job read back from the store at start-up; `body_hash` for a job with an idempotency key.
  void add_recovered(const std::shared_ptr<Job>& job, std::optional<std::size_t> body_hash);
  // Jobs whose state.json cannot be read: their keys stay taken (a retry must not create a second job).
  void add_damaged(const std::vector<JobStore::Damaged>& damaged);

  // A stored job (nullptr when unknown, damaged, or still being stored).
  std::shared_ptr<Job> find(const std::string& id) const;
  // A consistent copy of the job's record.
  JobRecord snapshot(const Job& job) const;
  bool is_queued(const Job& job) const;

  // Applies `change` to a copy of the job's record, writes it to state.json, and only then to the job in memory.
  // False (the job unchanged, `error` set) if the write fails.
  bool commit(const std::shared_ptr<Job>& job, const Change& change, bool durable, std::string* error = nullptr);
  // The solver's latest iteration, in short (the observer of a running job).
  void update_progress(Job& job, int iterations, nlohmann::json summary);
  // After the outcome is stored: the record as it now is; its dropped events are counted.
  JobRecord count_outcome(Job& job);
  // The job is done and its `end` event written: it may be deleted now (wakes remove() calls waiting for that),
  // and retention counts its `disk_bytes` when given.
  void settle(const std::shared_ptr<Job>& job, std::optional<std::int64_t> disk_bytes);

  // What a cancel does with the stored job `id` (set in `job`), decided under the registry's lock; `taken(job)`
  // says whether a worker holds it (the WorkerPool calls this with its own lock held).
  enum class CancelStep { stop_run, withdraw, in_progress, already_cancelled, already_done, not_found };
  // A QUEUED job nobody holds is marked as being cancelled (withdraw: the caller stores it CANCELLED).
  CancelStep cancel_step(const std::string& id, const std::function<bool(const Job&)>& taken,
                         std::shared_ptr<Job>& job);
  // A withdrawn job whose CANCELLED state could not be stored: true when it is still QUEUED.
  bool cancel_failed(Job& job);

  enum class RemoveOutcome { removed, not_found, not_done, store_error };
  // Deletes a finished (or damaged) job and its files.
  RemoveOutcome remove(const std::string& id, std::string& detail);

  // Listing, newest first, resuming after `after` (created_us, id) when given.
  struct Cursor {
    std::int64_t created_us = 0;
    std::string id;
  };
  struct Page {
    std::vector<JobRecord> jobs;
    std::optional<Cursor> next;  // set when more jobs follow
  };
  Page list(std::optional<JobState> state, std::size_t page_size, const std::optional<Cursor>& after) const;
  JobCounts counts() const;

  // Finished jobs retention deletes now (older than `max_age_seconds`, or beyond `max_bytes` in all, oldest
  // first; 0 = no limit); damaged jobs are left for the operator.
  std::vector<std::string> expired(double max_age_seconds, std::uint64_t max_bytes) const;

  // What is wrong with a job's files, if the store found damage.
  std::optional<std::string> damage(const std::string& id) const;
  // Records damage found while serving a job (a result file that is not what was written).
  void report_damage(const std::string& id, const std::string& problem);
  std::vector<std::pair<std::string, std::string>> damaged() const;  // (id, problem)
  std::int64_t events_dropped_total() const;

 private:
  using TimeKey = std::pair<std::int64_t, std::string>;

  RemoveOutcome remove_damaged_locked(std::unique_lock<std::mutex>& lock, const std::string& id, std::string& detail);
  void set_state_locked(Job& job, JobState state);
  void register_locked(const std::shared_ptr<Job>& job);
  void unregister_locked(const std::shared_ptr<Job>& job);
  void note_finished_locked(const std::shared_ptr<Job>& job);

  JobStore& store_;
  const std::uint64_t max_event_log_bytes_;

  mutable std::mutex mutex_;
  std::condition_variable settled_;  // a job's `end` event was written (it may now be deleted)
  std::unordered_map<std::string, std::shared_ptr<Job>> jobs_;
  std::map<TimeKey, std::shared_ptr<Job>> by_time_;         // (created_us, id), oldest first
  std::unordered_map<std::string, std::string> by_key_;     // idempotency key -> id
  std::unordered_map<std::string, std::size_t> body_hash_;  // id -> hash of job.json (jobs with a key)
  std::map<std::string, std::string> damaged_;              // id -> problem (see damage())
  std::map<TimeKey, std::shared_ptr<Job>> by_finished_;     // settled jobs by (finished_us, id): retention
  std::int64_t finished_bytes_ = 0;                         // their disk_bytes, summed
  std::array<std::int64_t, 5> state_counts_{};
  std::int64_t last_created_us_ = 0;
  std::int64_t events_dropped_total_ = 0;
};

}  // namespace contactd
