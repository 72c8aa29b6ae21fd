// The jobs the server knows, the queue of those waiting, and the worker threads that run them.
//
// Life of a job: submit() validates it, stores it (JobStore::create) and queues it (QUEUED); a worker takes it
// (RUNNING), runs contact::solve() with an observer that appends one `iteration` event per iteration, writes the
// result file and ends it SUCCEEDED, FAILED or CANCELLED with an `end` event. Mapping of the solver's stop reason:
//   converged                  -> SUCCEEDED, converged true
//   max_iterations, stagnation -> SUCCEEDED, converged false (the result file is written and useful)
//   error                      -> FAILED with the solver's message (no result file)
//   cancelled by the user      -> CANCELLED (the result file of the last iterate is written when the solver
//                                 returned one)
//   cancelled by the time limit-> FAILED with stop_reason "time_limit" (result file as for CANCELLED)
//   cancelled by shutdown      -> back to QUEUED on disk: it runs again, from the start, at the next start-up.
//   server died while running  -> QUEUED again at the next start-up, or FAILED with stop_reason "interrupted"
//                                 once that has happened max_attempts times (a job that kills the server).
//
// Every state change the API reports is on disk first: the new record is written to state.json, and only then
// does the job in memory change (commit()). A write that fails leaves the job as it was (the caller reports the
// store error), and a worker whose job cannot be stored as finished keeps trying until it can.
//
// Damage found in the store (a state.json that cannot be read, an event log or result file changed on disk) is
// kept in a registry: such jobs are never served from their files nor deleted by retention, and health() lists
// them for /readyz and /metrics.
//
// Thread safety: every public member may be called from any thread. One mutex guards the registry and every
// job's record; it is never held while solving, writing result files or waiting for a client.
#pragma once

#include "body_budget.hpp"
#include "job_record.hpp"
#include "job_store.hpp"
#include "metrics.hpp"

#include "contact/job.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include "mpi_job.hpp"

#include <unordered_map>
#include <utility>
#include <vector>

namespace contactd {

struct QueueSettings {
  int workers = 1;                     // jobs solved at once
  std::size_t max_queued = 100;        // QUEUED jobs beyond which submissions are refused (503)
  long max_dofs = 2'000'000;           // job::Limits::max_dofs
  int max_bodies = 512;                // job::Limits::max_bodies: a server's share of the machine, a setting
  int max_contacts = 2048;             // job::Limits::max_contacts
  double time_limit_seconds = 3600.0;  // per run; 0 = none
  int max_attempts = 3;                // runs cut short by the server dying, after which a job ends FAILED
  std::uint64_t max_event_log_bytes = 256u << 20;  // per job; iteration events beyond are not recorded
  double stuck_after_seconds = 60.0;   // a job still running this long after it was told to stop is "stuck"
  double retention_seconds = 7 * 86400.0;          // finished jobs older than this are deleted; 0 = kept
  std::uint64_t retention_bytes = 10ull << 30;     // finished jobs beyond this total are deleted, oldest first
  double janitor_interval_seconds = 10.0;          // how often retention runs
  MpiSettings mpi;                                 // jobs with parallel.ranks > 1 (mpi_job.hpp)
};

// What /readyz and /metrics report about the jobs.
struct QueueHealth {
  std::vector<std::pair<std::string, std::string>> damaged;  // (id, problem)
  std::vector<std::string> stuck;                            // ids of jobs that do not stop
  std::int64_t expired_total = 0;                            // jobs deleted by retention since start-up
  std::int64_t events_dropped_total = 0;                     // iteration events not recorded (log caps)
};

class JobQueue {
 public:
  // A worker parses its job again under one of `budget`'s validation slots (shared with the HTTP server).
  JobQueue(JobStore& store, Metrics& metrics, BodyBudget& budget, QueueSettings settings);
  ~JobQueue();
  JobQueue(const JobQueue&) = delete;
  JobQueue& operator=(const JobQueue&) = delete;

  // Reads the store back (before start()): finished jobs are kept as they are (an `end` event missing after a
  // crash is added); QUEUED and interrupted RUNNING jobs are queued again, oldest first.
  void recover();
  // Starts the workers and the time-limit watchdog.
  void start();
  // No job starts from now on; running jobs are cancelled and stored back as QUEUED. Waits up to `grace` for
  // the workers to finish that; returns false if one did not (the caller should then exit without joining).
  bool shutdown(std::chrono::milliseconds grace);

  struct Submission {
    enum class Outcome { accepted, replayed, invalid, key_conflict, key_damaged, queue_full, unavailable, store_error };
    Outcome outcome = Outcome::invalid;
    std::shared_ptr<Job> job;
    std::vector<contact::job::ValidationError> errors;  // invalid
    std::string detail;                                 // store_error; key_damaged: the job's id
  };
  // Queues a job validated by validate(). With a non-empty idempotency key already used: the same body returns
  // the existing job (replayed), another body is a key_conflict (key_damaged: that job's files are damaged).
  Submission submit(const std::string& body, contact::job::ParseResult parsed, const std::string& idempotency_key);

  // Validates only.
  contact::job::ParseResult validate(const std::string& body) const;

  // A stored job (nullptr when unknown, damaged, or still being stored).
  std::shared_ptr<Job> find(const std::string& id) const;
  // What is wrong with a job's files, if the store found damage.
  std::optional<std::string> damage(const std::string& id) const;
  // Records damage found while serving a job (a result file that is not what was written).
  void report_damage(const std::string& id, const std::string& problem);
  QueueHealth health() const;
  // A consistent copy of the job's record, and its place in the queue (1 = next; 0 when not waiting).
  JobRecord snapshot(const Job& job, int* queue_position = nullptr) const;

  enum class CancelOutcome { cancelled, cancelling, already_cancelled, already_done, not_found, store_error };
  CancelOutcome cancel(const std::string& id);

  enum class RemoveOutcome { removed, not_found, not_done, store_error };
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
  int workers() const { return settings_.workers; }
  int workers_busy() const;
  int workers_alive() const { return workers_alive_.load(); }
  bool stopping() const;

 private:
  using TimeKey = std::pair<std::int64_t, std::string>;

  using Change = std::function<void(JobRecord&)>;

  void worker_loop();
  void watchdog_loop();
  void watch_running_locked(std::chrono::steady_clock::time_point now);
  void apply_retention();
  void run(const std::shared_ptr<Job>& job);
  // The job parsed again (it was valid when submitted) under a validation slot, as a submission is. A cancel or
  // the time limit while it waits for the slot or is parsed ends it before any solve: nullopt, `result` says why.
  std::optional<contact::Problem> parse_for_run(Job& job, contact::Result& result);
  // Sets job->settled under the queue lock and wakes remove() calls waiting for it.
  void mark_settled(const std::shared_ptr<Job>& job);
  void finish(const std::shared_ptr<Job>& job, JobRecord outcome);
  void requeue_after_shutdown(const std::shared_ptr<Job>& job);
  // Applies `change` to a copy of the job's record, writes it to state.json, and only then to the job in memory.
  // False (the job unchanged, `error` set) if the write fails.
  bool commit(const std::shared_ptr<Job>& job, const Change& change, bool durable, std::string* error = nullptr);
  // commit() until it succeeds or the queue stops (a worker finishing a job on a full disk); false if stopped.
  bool commit_patiently(const std::shared_ptr<Job>& job, const Change& change);
  std::shared_ptr<Job> make_job(const JobRecord& record);
  void recover_job(const std::shared_ptr<Job>& job, int& requeued);
  void set_state_locked(Job& job, JobState state);
  void register_locked(const std::shared_ptr<Job>& job);
  void unregister_locked(const std::shared_ptr<Job>& job);
  void note_finished_locked(const std::shared_ptr<Job>& job);

  JobStore& store_;
  Metrics& metrics_;
  BodyBudget& budget_;
  const QueueSettings settings_;

  mutable std::mutex mutex_;
  std::condition_variable work_;      // a job was queued, or stopping
  std::condition_variable watchdog_;  // stopping
  std::condition_variable idle_;      // a worker finished a job or exited
  std::condition_variable settled_;   // a job's `end` event was written (it may now be deleted)
  std::unordered_map<std::string, std::shared_ptr<Job>> jobs_;
  std::map<TimeKey, std::shared_ptr<Job>> by_time_;         // (created_us, id), oldest first
  std::unordered_map<std::string, std::string> by_key_;     // idempotency key -> id
  std::unordered_map<std::string, std::size_t> body_hash_;  // id -> hash of job.json (jobs with a key)
  std::map<std::string, std::string> damaged_;              // id -> problem (see damage())
  std::map<TimeKey, std::shared_ptr<Job>> by_finished_;     // settled jobs by (finished_us, id): retention
  std::int64_t finished_bytes_ = 0;                          // their disk_bytes, summed
  std::vector<std::string> stuck_;
  std::int64_t expired_total_ = 0;
  bool retention_due_ = false;  // a job was settled: the janitor checks retention at once
  std::int64_t events_dropped_total_ = 0;
  std::deque<std::shared_ptr<Job>> queue_;
  std::vector<std::shared_ptr<Job>> running_;
  std::array<std::int64_t, 5> state_counts_{};
  std::int64_t last_created_us_ = 0;
  bool started_ = false;
  bool stopping_ = false;
  std::vector<std::thread> threads_;
  std::thread watchdog_thread_;
  std::atomic<int> workers_alive_{0};
};

}  // namespace contactd
